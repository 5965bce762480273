"""No result is overwritten by accident: every writing command, run twice into the same
place, refuses the second time with one line naming ``--force`` (exit 2, no traceback, the
first run's files untouched), and with ``--force`` writes again."""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import pytest
from synthetic_results import write_results
from typer.testing import CliRunner

from pushctl.cli import app
from pushctl.control.gains import PDGains, gains_toml
from pushctl.reproduce import plan as plan
from pushctl.reproduce import steps as reproduce
from pushctl.reproduce.plan import MANIFEST, QUICK

runner = CliRunner()


def _refused(result, *fragments: str) -> None:
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("error:"), result.stderr
    assert "--force" in lines[0]
    for fragment in fragments:
        assert fragment in lines[0], lines[0]


def _snapshot(*paths: Path) -> dict[Path, bytes]:
    return {path: path.read_bytes() for path in paths}


def test_plan_refuses_its_own_earlier_files_without_force(tmp_path: Path) -> None:
    out, plot = tmp_path / "plan.csv", tmp_path / "plan.png"
    args = ["plan", "--goal", "0.62,0.03,30", "--out", str(out), "--plot", str(plot)]
    first = runner.invoke(app, args)
    assert first.exit_code == 0, first.output
    before = _snapshot(out, plot)
    _refused(runner.invoke(app, args), str(out), "already exists")
    assert _snapshot(out, plot) == before
    # Only the plot existing is enough to refuse too.
    out.unlink()
    _refused(runner.invoke(app, args), str(plot))
    assert not out.exists()
    again = runner.invoke(app, [*args, "--force"])
    assert again.exit_code == 0, again.output
    assert out.read_bytes() == before[out]  # --force is not recorded: the same bytes


def test_simulate_twice_into_one_file(tmp_path: Path) -> None:
    gains = tmp_path / "gains.toml"
    gains.write_text(gains_toml(PDGains(kp=300, kv=200, kx_linear=50, kx_angular=50), "test"))
    out = tmp_path / "trace.csv"
    args = ["simulate", "--gains", str(gains), "--duration", "1", "--scenario", "3"]
    args += ["--out", str(out)]
    first = runner.invoke(app, args)
    assert first.exit_code == 0, first.output
    before = out.read_bytes()
    _refused(runner.invoke(app, args), str(out))
    assert out.read_bytes() == before
    again = runner.invoke(app, [*args, "--force"])
    assert again.exit_code == 0, again.output
    assert out.read_bytes() == before


def test_tune_pd_refuses_an_existing_gains_file(tmp_path: Path) -> None:
    out = tmp_path / "gains.toml"
    out.write_text("# hand-tuned, keep\n")
    budget = ["--objects", "cube", "--profiles", "chirp", "--per-case", "1", "--duration", "1"]
    args = ["tune-pd", *budget, "--max-rounds", "0", "--out", str(out)]
    _refused(runner.invoke(app, args), str(out))
    assert out.read_text() == "# hand-tuned, keep\n"
    forced = runner.invoke(app, [*args, "--force"])
    assert forced.exit_code == 0, forced.output
    assert out.read_text().startswith("# made by: pushctl tune-pd")
    _refused(runner.invoke(app, args), str(out))


def test_evaluate_twice_into_one_directory(tmp_path: Path) -> None:
    out = tmp_path / "evaluation"
    tiny = ["--object", "cube", "--profile", "chirp", "--trials", "1", "--controller", "pd"]
    args = ["evaluate", *tiny, "--plant", "sim", "--out", str(out)]
    first = runner.invoke(app, args)
    assert first.exit_code == 0, first.output
    files = sorted(out.iterdir())
    before = _snapshot(*files)
    _refused(runner.invoke(app, args), str(out), "not empty")
    assert _snapshot(*files) == before
    # A directory holding anything else is refused as well: it is not this run's.
    other = tmp_path / "other"
    other.mkdir()
    (other / "notes.txt").write_text("keep")
    _refused(runner.invoke(app, [*args[:-1], str(other)]), str(other))
    assert [p.name for p in other.iterdir()] == ["notes.txt"]
    again = runner.invoke(app, [*args, "--force"])
    assert again.exit_code == 0, again.output
    assert _snapshot(*files) == before


def test_report_twice_into_one_directory(tmp_path: Path) -> None:
    results = write_results(tmp_path / "results")
    out = tmp_path / "out"
    args = ["report", "--in", str(results), "--out", str(out)]
    first = runner.invoke(app, args)
    assert first.exit_code == 0, first.output
    table = out / "table3.csv"
    before = table.read_bytes()
    _refused(runner.invoke(app, args), "table3.csv", "already exists")
    # Into its own input directory (as make reproduce-tables does): the inputs do not count, an
    # earlier report's tables do.
    into_inputs = runner.invoke(app, ["report", "--in", str(results), "--out", str(results)])
    assert into_inputs.exit_code == 0, into_inputs.output
    _refused(runner.invoke(app, ["report", "--in", str(results), "--out", str(results)]))
    table.write_text("stale\n")
    again = runner.invoke(app, [*args, "--force"])
    assert again.exit_code == 0, again.output
    assert table.read_bytes() == before


def test_train_twice_into_one_run_directory_and_resume(tmp_path: Path) -> None:
    preset = tmp_path / "tiny.toml"
    preset.write_text(
        "[train]\nepisodes = 2\ncheckpoint_every = 1\npd_every = 2\nvalidate_every = 2\n"
        'validation_per_cell = 1\n[env]\nobjects = ["cube"]\nprofiles = ["constant"]\n'
        "duration = 1.0\n[ddpg]\nhidden = [8, 8]\nbatch_size = 16\nbuffer_size = 500\n"
        "warmup_steps = 100\nupdates_per_step = 0.05\n"
    )
    out = tmp_path / "run"
    args = ["train", "--preset", str(preset), "--out", str(out)]
    first = runner.invoke(app, args)
    assert first.exit_code == 0, first.output
    before = _snapshot(*sorted(out.iterdir()))
    _refused(runner.invoke(app, args), str(out), "--resume")
    assert _snapshot(*sorted(out.iterdir())) == before
    # Resuming is not overwriting: the run goes on in its own directory.
    resumed = runner.invoke(app, ["train", "--resume", "--episodes", "3", "--out", str(out)])
    assert resumed.exit_code == 0, resumed.output
    forced = runner.invoke(app, [*args, "--force"])
    assert forced.exit_code == 0, forced.output
    assert _snapshot(*sorted(out.iterdir())) == before  # started over: the same bytes


# --- pushctl reproduce (make reproduce-tables) ----------------------------------------------------


def _setup(tmp_path: Path):
    return replace(QUICK, run=tmp_path / "runs" / "quick", results=tmp_path / "results-quick")


def _fake_steps(record: list[list[str]]):
    """Each step as a no-op subprocess; ``record`` receives the real argv."""
    real = plan.steps

    def steps(setup):
        listed = real(setup)
        record.extend(argv for _, argv in listed)
        return [(name, [sys.executable, "-c", "pass"]) for name, _ in listed]

    return steps


def test_reproduce_refuses_a_results_directory_it_did_not_make(tmp_path: Path) -> None:
    setup = _setup(tmp_path)
    assert plan.check_owned(setup) is None  # absent
    setup.results.mkdir()
    assert plan.check_owned(setup) is None  # empty
    (setup.results / "table3.csv").write_text("someone else's\n")
    refusal = plan.check_owned(setup)
    assert refusal is not None and "--force" in refusal and len(refusal.splitlines()) == 1
    assert plan.check_owned(replace(setup, force=True)) is None


def test_reproduce_resumes_into_what_it_made(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    setup = _setup(tmp_path)
    record: list[list[str]] = []
    fake = _fake_steps(record)
    monkeypatch.setattr(reproduce, "steps", fake)
    monkeypatch.setattr(reproduce, "copy_training", lambda setup: None)
    monkeypatch.setattr(reproduce, "compress_steps", lambda setup: None)  # no steps.csv here
    reproduce.reproduce(setup)
    monkeypatch.undo()
    manifest = (setup.results / MANIFEST).read_text()
    assert "all steps succeeded" in manifest and str(setup.run) in manifest
    train, evaluate, report = record
    assert "--resume" not in train and "--force" not in train  # a fresh run
    assert evaluate[-1] == "--force" and report[-1] == "--force"
    (setup.results / "table3.csv").write_text("an earlier reproduction's\n")
    assert plan.check_owned(setup) is None  # its own manifest is there
    # Stopped before the run's first checkpoint: its files are this reproduction's.
    setup.run.mkdir(parents=True)
    (setup.run / "curve.csv").write_text("partial\n")
    assert plan.steps(setup)[0][1][-1] == "--force"
    seed_run = plan.seed_run(setup, setup.seeds[0])  # train --seeds: RUN/seed-K/
    seed_run.mkdir(parents=True)
    (seed_run / "checkpoint.pt").write_bytes(b"x")
    assert plan.steps(setup)[0][1][-1] == "--resume"
    # A run directory the manifest does not name is left to train's own refusal.
    other = replace(setup, run=tmp_path / "runs" / "other")
    other.run.mkdir()
    (other.run / "curve.csv").write_text("someone else's\n")
    assert other.run.name not in (setup.results / MANIFEST).read_text()
    assert "--force" not in plan.steps(other)[0][1]


def test_reproduce_refuses_with_one_line(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    setup = _setup(tmp_path)
    setup.results.mkdir()
    (setup.results / "tables.md").write_text("keep\n")
    monkeypatch.setattr(reproduce, "QUICK", setup)
    monkeypatch.setattr(reproduce, "reproduce", lambda setup: pytest.fail("must not run"))
    refused = runner.invoke(app, ["reproduce", "--quick"])
    _refused(refused)
    assert (setup.results / "tables.md").read_text() == "keep\n"
