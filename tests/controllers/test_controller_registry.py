"""The controller registry: one name → one type, read by the report, the command line and
the evaluation. A toy controller registered in one module (``toy_controller.py``) runs
through ``simulate``, ``evaluate`` and ``report`` with nothing else touched."""

from __future__ import annotations

import copy
import importlib
import sys
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from pushctl.cli import app
from pushctl.control.gains import load_gains
from pushctl.controllers import (
    PushSetup,
    controller_entry,
    controller_names,
    paper_controllers,
    register_controller,
    unregister_controller,
)
from pushctl.controllers.drive import build_controllers, push_controllers, reset
from pushctl.errors import ConfigError
from pushctl.rl.config import DDPGConfig
from pushctl.rl.ddpg import DDPGAgent
from pushctl.rl.policy import write_policy
from pushctl.task.env import PushEnv
from pushctl.task.env_config import EnvConfig
from pushctl.task.spaces import observation_entries, scales

runner = CliRunner()


@pytest.fixture
def toy() -> Iterator[str]:
    """The toy controller registered for one test, and gone after it."""
    module = importlib.import_module("toy_controller")
    try:
        yield module.NAME
    finally:
        unregister_controller(module.NAME)
        sys.modules.pop("toy_controller", None)


def _policy(path: Path) -> Path:
    """An untrained actor with a 2 s push: the evaluation's push length."""
    entries = observation_entries(2, reference_offset=True)
    agent = DDPGAgent(len(entries), 3, DDPGConfig(hidden=(8, 8)), seed=0, obs_scale=scales(entries))
    write_policy(path, agent.actor_state(), EnvConfig(duration=2.0), "# made by: a test run")
    return path


def test_the_registry_holds_the_paper_s_three_in_the_tables_order() -> None:
    assert controller_names() == paper_controllers() == ("pd", "feedback", "rl")
    assert controller_entry("rl").needs_policy and not controller_entry("pd").needs_policy
    assert not controller_entry("rl").any_pusher and controller_entry("feedback").any_pusher
    assert controller_entry("feedback").load_gains is not None
    with pytest.raises(ConfigError, match="unknown controller 'mpc'; accepted: pd, feedback, rl"):
        controller_entry("mpc")


def test_a_name_is_registered_once_and_is_a_lower_case_word(toy: str) -> None:
    assert controller_names() == ("pd", "feedback", "rl", toy)
    assert paper_controllers() == ("pd", "feedback", "rl")  # `--controller all` unchanged
    with pytest.raises(ConfigError, match="registered already"):
        register_controller(toy, label="x", colour="k", summary="x")(object)
    for bad in ("Toy", "all", "my-law"):
        with pytest.raises(ConfigError, match="lower-case word"):
            register_controller(bad, label="x", colour="k", summary="x")(object)
    assert controller_names() == ("pd", "feedback", "rl", toy)


def test_a_zero_residual_pushes_as_pd_from_the_re_landed_start_to_the_bit(toy: str) -> None:
    """Through the gate and the reference path, a zero residual changes nothing: the toy's
    push is the PD law's from where the reset re-landed the prongs (PD-only's own starts
    where the approach landed them), the same floats."""
    gains = load_gains()
    setup = PushSetup(EnvConfig(duration=1.0, stream="evaluation"), gains)
    env = PushEnv(setup.config, gains)
    start = reset(env, {"object": "wedge", "profile": "chirp", "scenario_seed": 4})
    assert env.episode is not None
    pd_relanded = copy.deepcopy(env.episode).finish()
    runs = push_controllers(build_controllers(("pd", toy), setup), start)
    toy_trace = runs[toy][0].trace
    assert np.array_equal(toy_trace.object_pose, pd_relanded.object_pose)
    assert np.array_equal(toy_trace.contact_forces, pd_relanded.contact_forces)
    assert not np.array_equal(runs["pd"][0].trace.object_pose, toy_trace.object_pose)
    assert 0.0 <= runs[toy][0].gate_share <= 1.0


def test_a_toy_controller_runs_through_simulate_evaluate_and_report(
    toy: str, tmp_path: Path
) -> None:
    trace = tmp_path / "trace.csv"
    done = runner.invoke(
        app,
        ["simulate", "--controller", toy, "--duration", "1", "--scenario", "1",
         "--out", str(trace)],
    )  # fmt: skip
    assert done.exit_code == 0, done.output
    assert len(pd.read_csv(trace, comment="#")) == 101  # rows t = 0 … 1 s

    evaluation = tmp_path / "evaluation"
    done = runner.invoke(
        app,
        ["evaluate", "--object", "cube", "--profile", "chirp", "--plant", "sim",
         "--trials", "2", "--controller", f"pd,rl,{toy}",
         "--policy", str(_policy(tmp_path / "policy.pt")), "--out", str(evaluation)],
    )  # fmt: skip
    assert done.exit_code == 0, done.output
    assert "TOY" in done.output  # the summary table's row
    trials = pd.read_csv(evaluation / "trials.csv", comment="#")
    assert list(trials["controller"]) == ["pd", "pd", "rl", "rl", toy, toy]
    # paired: the same scenarios, goals and plants
    for column in ("seed", "goal_dx", "goal_dtheta", "mu_ground"):
        assert trials[column].iloc[4:].tolist() == trials[column].iloc[:2].tolist()

    report = tmp_path / "report"
    done = runner.invoke(app, ["report", "--in", str(evaluation), "--out", str(report)])
    assert done.exit_code == 0, done.output
    table3 = pd.read_csv(report / "table3.csv", comment="#")
    # the paper's three first (feedback did not run: empty), then the toy
    errors = [c for c in table3.columns if c.startswith("translation_error_")]
    assert errors[:4] == [f"translation_error_{c}" for c in ("pd", "feedback", "rl", toy)]
    assert table3[f"translation_error_{toy}"].notna().all()
    assert table3["translation_error_feedback"].isna().all()
    assert (report / "fig6_tracking.png").stat().st_size > 0
    assert "translation toy (zero residual)" in (report / "tables.md").read_text()


def test_an_unregistered_controller_is_refused_in_one_line(tmp_path: Path) -> None:
    done = runner.invoke(app, ["simulate", "--controller", "toy", "--scenario", "1"])
    assert done.exit_code == 2
    assert "unknown controller 'toy'; accepted: pd, feedback, rl" in done.stderr


@pytest.mark.parametrize("controller", ["feedback", "rl"])
def test_simulate_runs_a_residual_controller_on_mujoco(controller: str, tmp_path: Path) -> None:
    """simulate builds its environment on the evaluation stream, as its scenarios are, so
    the MuJoCo plant (evaluation only) takes the law and a policy as it takes PD-only."""
    out = tmp_path / "trace.csv"
    done = runner.invoke(
        app,
        ["simulate", "--controller", controller, "--plant", "mujoco", "--duration", "0.5",
         "--scenario", "2", "--out", str(out)],
    )  # fmt: skip
    assert done.exit_code == 0, done.output
    assert len(pd.read_csv(out, comment="#")) == 51
