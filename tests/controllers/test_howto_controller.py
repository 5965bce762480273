"""docs/howto/add-a-controller.md's example runs as written: its controller module, executed
from the page with its gains file from the page, registers and pushes."""

from __future__ import annotations

import re
import types
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from pushctl.control.gains import load_gains
from pushctl.controllers import PushSetup, controller_entry, unregister_controller
from pushctl.controllers.drive import push_scenario
from pushctl.episode.draw import draw_scenario
from pushctl.episode.metrics import compute_metrics
from pushctl.task.env_config import EnvConfig

HOWTO = Path(__file__).resolve().parents[2] / "docs" / "howto" / "add-a-controller.md"


def _blocks(language: str) -> list[str]:
    return re.findall(rf"```{language}\n(.*?)```", HOWTO.read_text(), re.S)


@pytest.fixture
def proportional(tmp_path: Path) -> Iterator[types.ModuleType]:
    """The page's controller module, its gains file written from the page to ``tmp_path``."""
    module = types.ModuleType("proportional")
    source = next(block for block in _blocks("python") if "register_controller(" in block)
    module.__dict__["__file__"] = str(tmp_path / "proportional.py")
    try:
        exec(compile(source, "add-a-controller.md", "exec"), module.__dict__)
        gains = tmp_path / "proportional_gains.toml"
        gains.write_text(_blocks("toml")[0])
        module.GAINS = gains
        yield module
    finally:
        unregister_controller("proportional")


def test_the_howto_s_controller_registers_and_pushes(proportional: types.ModuleType) -> None:
    entry = controller_entry("proportional")
    assert entry.summary == "PD + P on the pose" and not entry.paper
    assert entry.load_gains is not None and entry.load_gains() == 0.5
    scenario, _ = draw_scenario(3, "evaluation", "cube", "chirp", duration=1.0)
    setup = PushSetup(EnvConfig(), load_gains(), controller_gains={"proportional": 0.5})
    trace, _ = push_scenario("proportional", scenario, setup)
    metrics = compute_metrics(trace)
    assert trace.n_steps == 100 and np.isfinite(metrics.translation_error_pct)
    assert "from pushctl.controllers import proportional" in "".join(_blocks("python"))
