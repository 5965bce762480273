"""Output targets under faults: a sweep directory is held by one command at a time, and a
target that cannot be written (a read-only directory) is one line naming the file asked
for, with the earlier good file intact."""

from __future__ import annotations

import errno
import subprocess
import sys
from pathlib import Path

import pytest
from fault_helpers import lock_held_elsewhere, one_error_line, recorded_pushes
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


def test_a_second_report_into_a_directory_not_made_yet_is_refused(tmp_path, monkeypatch):
    from synthetic_results import write_results

    from pushctl.cli import report_steps

    root = write_results(tmp_path / "results")
    out = tmp_path / "new" / "report"
    command = ["report", "--in", str(root), "--out", str(out)]
    make_report, second = report_steps.make_report, []

    def while_another_reports(*args, **kwargs):  # the first holds --out: a second starts
        second.append(subprocess.run([sys.executable, "-m", "pushctl.cli", *command],
                                     capture_output=True, text=True, timeout=120))  # fmt: skip
        return make_report(*args, **kwargs)

    monkeypatch.setattr(report_steps, "make_report", while_another_reports)
    first = runner.invoke(app, command)
    assert first.exit_code == 0, first.output
    assert second[0].returncode == 2, second[0].stderr
    lines = second[0].stderr.strip().splitlines()
    assert len(lines) == 1 and "in use by another pushctl command" in lines[0], lines
    assert not [p for p in out.iterdir() if p.name.endswith(".lock")]


def test_a_refused_report_leaves_no_directory_behind(tmp_path):
    out = tmp_path / "new" / "report"
    result = runner.invoke(app, ["report", "--in", str(tmp_path / "none"), "--out", str(out)])
    one_error_line(result, "no such directory")
    assert not (tmp_path / "new").exists()


@pytest.mark.parametrize(
    ("args", "files", "fragment"),
    [
        (["plan", "--object", "cube", "--goal", "1e308,0,0"], {}, "--goal: position"),
        (["simulate", "--object", "cube", "--goal", "0.6,0,1e9"], {}, "--goal: angle"),
        (["train", "--episodes", "1000000000000", "--out", "{tmp}/run"], {}, "--episodes"),
        (["train", "--preset", "{tmp}/big.toml", "--out", "{tmp}/run"],
         {"big.toml": "[train]\n[env]\n[ddpg]\nbuffer_size = 9000000000000000\n"},
         "replay buffer size"),
        (["plan", "--object", "cube", "--goal", "0.62,0.03,30", "--pusher", "{tmp}/p.toml"],
         {"p.toml": "width = 1e9\n"}, "pusher plate size"),
        (["realdata", "fit", "--data", "{tmp}", "--out", "{tmp}/f.toml", "--split-seed", "-1"],
         {}, "--split-seed"),
        (["realdata", "score", "--data", "{tmp}", "--friction", "{tmp}/fit.toml", "--out",
          "{tmp}/score"], {"fit.toml": "[surface.felt]\nmu_contact = 1e9\n"},
         "friction coefficient"),
    ],
    ids=["goal-1e308", "angle-1e9", "episodes-1e12", "buffer-9e15", "plate-1e9-m",
         "split-seed-negative", "mu-1e9"],
)  # fmt: skip
def test_an_absurd_value_is_one_line_before_any_work(args, files, fragment, tmp_path):
    for name, text in files.items():
        (tmp_path / name).write_text(text)
    args = [arg.replace("{tmp}", str(tmp_path)) for arg in args]
    one_error_line(runner.invoke(app, args), fragment)
    assert not (tmp_path / "run").exists() and not (tmp_path / "score").exists()


def test_recorded_pushes_cut_at_a_line_boundary_are_not_scored(tmp_path):
    data = recorded_pushes(tmp_path / "data", 40)
    fit = tmp_path / "fit.toml"
    fitted = runner.invoke(app, ["realdata", "fit", "--data", str(data), "--out", str(fit),
                                 "--workers", "1", "--rim-weights", "0"])  # fmt: skip
    assert fitted.exit_code == 0, fitted.output
    pushes = data / "mit" / "pushes.csv"
    lines = pushes.read_text().splitlines(keepends=True)
    pushes.write_text("".join(lines[:-3]))  # the last three pushes gone, every row whole
    score = ["realdata", "score", "--data", str(data), "--friction", str(fit),
             "--out", str(tmp_path / "score"), "--workers", "1"]  # fmt: skip
    one_error_line(runner.invoke(app, score), str(pushes), "37 pushes", "40", "cut short")
    assert not (tmp_path / "score").exists()


def test_an_interrupted_evaluation_resumes_to_the_same_bytes(tmp_path, monkeypatch):
    from pushctl.evaluation import evaluate as module

    args = ["evaluate", "--object", "cube", "--profile", "chirp", "--trials", "3",
            "--controller", "pd", "--plant", "sim"]  # fmt: skip
    whole = tmp_path / "whole"
    assert runner.invoke(app, [*args, "--out", str(whole)]).exit_code == 0
    run, calls = module._Context.run, []

    def stopped_at_the_third(self, job):
        calls.append(job)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return run(self, job)

    monkeypatch.setattr(module._Context, "run", stopped_at_the_third)
    out = tmp_path / "evaluation"
    stopped = runner.invoke(app, [*args, "--out", str(out)])
    assert stopped.exit_code == 130, stopped.output
    assert "2 of 3 trials kept" in stopped.stderr and "--resume" in stopped.stderr
    monkeypatch.undo()
    one_error_line(runner.invoke(app, [*args, "--out", str(out)]), "--resume")
    resumed = runner.invoke(app, [*args, "--resume", "--out", str(out)])
    assert resumed.exit_code == 0, resumed.output
    for name in ("trials.csv", "steps.csv"):
        assert (out / name).read_bytes() == (whole / name).read_bytes(), name
    assert sorted(p.name for p in out.iterdir()) == ["steps.csv", "trials.csv"]


def test_a_second_reproduction_is_refused_while_the_first_holds_its_results(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    results = tmp_path / "results-quick"
    results.mkdir()
    with lock_held_elsewhere(results / LOCK_NAME):
        refused = runner.invoke(app, ["reproduce", "--quick"])
        one_error_line(refused, "results-quick", "in use by another pushctl command")
        assert sorted(p.name for p in results.iterdir()) == [LOCK_NAME]  # nothing written
