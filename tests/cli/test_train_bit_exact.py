"""The same `pushctl train` command and seed write the same bytes.

Two runs of a shortened `paper` preset (its collectors, learner, checkpoints and validation,
with a short warm-up so that learning updates run) in fresh processes, each into a run
directory of its own (the provenance line does not name --out), must write identical files.
The full-length check (200 `paper` episodes) is described in docs/reproducibility-and-speed.md,
*Bit-exact long runs*.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from pushctl.rl.presets import preset_path

SHORTER = {  # [train] and [ddpg] keys of the paper preset replaced; everything else is the paper's
    "episodes": "6",
    "checkpoint_every": "3",
    "validate_every": "3",
    "validation_per_cell": "1",
    "warmup_steps": "300",
    "critic_burn_in": "100",
}


def _short_paper_preset() -> str:
    text = preset_path("paper").read_text(encoding="utf-8")
    for key, value in SHORTER.items():
        text, count = re.subn(rf"(?m)^{key}\s*=.*$", f"{key} = {value}", text)
        assert count == 1, key
    return text


def _train(cwd: Path) -> dict[str, bytes]:
    cwd.mkdir()
    (cwd / "preset.toml").write_text(_short_paper_preset(), encoding="utf-8")
    command = [sys.executable, "-c", "from pushctl.cli import app; app()", "train",
               "--preset", "preset.toml", "--seed", "3", "--out", f"run-{cwd.name}"]  # fmt: skip
    env = {**os.environ, "PYTHONHASHSEED": cwd.name[-1]}  # differ between the two runs
    done = subprocess.run(command, cwd=cwd, env=env, capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr[-2000:]
    return {path.name: path.read_bytes() for path in sorted((cwd / f"run-{cwd.name}").iterdir())}


@pytest.mark.slow
def test_two_runs_of_one_seed_write_the_same_bytes(tmp_path):
    first, second = _train(tmp_path / "run1"), _train(tmp_path / "run2")
    assert {"curve.csv", "validation.csv", "policy.pt", "checkpoint.pt"} <= set(first)
    assert sorted(first) == sorted(second)
    differing = [name for name in first if first[name] != second[name]]
    assert differing == []
    # provenance, header, 3 validations: episode 0 (the zero residual on the preset's base
    # law, the feedback law), 3 and 6
    assert first["validation.csv"].count(b"\n") == 5
