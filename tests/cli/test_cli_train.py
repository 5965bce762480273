"""``pushctl train`` of one seed: it runs in the calling process without Ray, and says what
the policy file it wrote holds (here the law: no update ever runs, so no actor can beat it)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

LAW_ONLY = """
[train]
episodes = 2
checkpoint_every = 2
pd_every = 2
workers = 2
validate_every = 2
validation_per_cell = 1

[env]
objects = ["cube"]
profiles = ["constant"]
duration = 2.0
action_repeat = 10
base_law = "feedback"

[ddpg]
hidden = [16, 16]
warmup_steps = 100000
actor_final_init = 0.0
"""
"""Every episode in the warm-up: every actor validated is the zero residual on the law."""

TRAIN_AND_CHECK = """
import sys
from pushctl.cli import app
try:
    app(["train", "--preset", "law.toml", "--out", "run"])
except SystemExit as exit:
    assert not exit.code, exit.code
assert "ray" not in sys.modules, "a one-seed run imported Ray"
"""


def test_one_seed_trains_without_ray_and_names_the_law(tmp_path: Path) -> None:
    (tmp_path / "law.toml").write_text(LAW_ONLY)
    done = subprocess.run(
        [sys.executable, "-c", TRAIN_AND_CHECK],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        check=False,
        env={**os.environ, "COLUMNS": "300"},
    )
    assert done.returncode == 0, done.stderr[-2000:]
    assert (tmp_path / "run" / "policy.pt").is_file()
    out = " ".join(done.stdout.split())
    assert "no actor beat the law: this policy is the law" in out or "PD-only" in out, out


def test_workers_are_one_runs_collectors(tmp_path: Path) -> None:
    from typer.testing import CliRunner

    from pushctl.cli import app

    runner = CliRunner()
    out = ["--out", str(tmp_path / "run")]
    too_many = runner.invoke(app, ["train", "--workers", "9", *out])
    assert too_many.exit_code == 2 and "--workers must be an integer in 0..8" in too_many.output
    with_seeds = runner.invoke(app, ["train", "--seeds", "0,1", "--workers", "2", *out])
    assert with_seeds.exit_code == 2 and "--workers is for one seed's run" in with_seeds.output
    assert not (tmp_path / "run").exists()
