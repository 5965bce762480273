"""Output targets under faults: a sweep directory is held by one command at a time, and a
target that cannot be written (a read-only directory) is one line naming the file asked
for, with the earlier good file intact."""

from __future__ import annotations

import errno
from pathlib import Path

from fault_helpers import lock_held_elsewhere, one_error_line
from typer.testing import CliRunner

from pushctl.cli import app
from pushctl.files.output_guard import LOCK_NAME

ROOT = Path(__file__).resolve().parents[2]
runner = CliRunner()


def test_a_second_sweep_into_a_held_directory_is_refused(tmp_path):
    out = tmp_path / "sweep"
    out.mkdir()
    sweep = ["sweep", str(ROOT / "experiments" / "sweep_gate.toml"), "--out", str(out)]
    with lock_held_elsewhere(out / LOCK_NAME):
        one_error_line(runner.invoke(app, sweep), str(out), "in use by another pushctl command")
        resumed = runner.invoke(app, [*sweep, "--resume"])
        one_error_line(resumed, "in use by another pushctl command")
        assert sorted(p.name for p in out.iterdir()) == [LOCK_NAME]  # nothing written


def test_a_sweep_directory_with_results_asks_for_resume(tmp_path):
    out = tmp_path / "sweep"
    out.mkdir()
    (out / "trials.csv").write_text("kept\n")
    sweep = ["sweep", str(ROOT / "experiments" / "sweep_gate.toml"), "--out", str(out)]
    one_error_line(runner.invoke(app, sweep), "already holds a sweep", "--resume")
    assert (out / "trials.csv").read_text() == "kept\n"


def test_a_read_only_target_names_the_file_and_keeps_the_old_one(tmp_path, monkeypatch):
    out = tmp_path / "evaluation"
    args = ["evaluate", "--object", "cube", "--profile", "chirp", "--trials", "1",
            "--controller", "pd", "--plant", "sim", "--out", str(out)]  # fmt: skip
    first = runner.invoke(app, args)
    assert first.exit_code == 0, first.output
    kept = {p.name: p.read_bytes() for p in out.iterdir() if p.suffix == ".csv"}
    mkdir = Path.mkdir

    def read_only(self, *a, **k):  # the tests may run as root, whom chmod does not stop
        if self.name.endswith(".tmp"):
            raise PermissionError(errno.EACCES, "Permission denied", str(self))
        return mkdir(self, *a, **k)

    monkeypatch.setattr(Path, "mkdir", read_only)
    line = one_error_line(runner.invoke(app, [*args, "--force"]), f"cannot write {out}",
                          "Permission denied")  # fmt: skip
    assert ".tmp" not in line
    assert {p.name: p.read_bytes() for p in out.iterdir() if p.suffix == ".csv"} == kept
