"""``pushctl reproduce`` (``make reproduce-tables``): the commands it types, resuming a run,
copying the training files, and a manifest written whether the steps succeed or fail."""

from __future__ import annotations

import gzip
import os
import sys
from dataclasses import replace
from datetime import datetime, timezone
from pathlib import Path

import pytest
from typer.testing import CliRunner

from pushctl.cli import app
from pushctl.machine import machine_description
from pushctl.reproduce import manifest as manifests
from pushctl.reproduce import plan as plan
from pushctl.reproduce import steps as reproduce
from pushctl.reproduce.plan import FULL, MANIFEST, QUICK, TRAINING_FILES, Setup

runner = CliRunner()


def test_the_full_setup_is_the_paper_s_protocol(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)  # no runs/paper here: a fresh run
    assert [name for name, _ in plan.steps(FULL)] == ["train", "evaluate", "report"]
    (tmp_path / "benchmarks").mkdir()  # a checkout: its bench runs too
    (tmp_path / "benchmarks" / "suite.py").write_text("")
    commands = {name: argv for name, argv in plan.steps(FULL)}
    assert list(commands) == ["train", "evaluate", "report", "bench"]
    assert commands["bench"][1:4] == ["-m", "benchmarks.suite", "--profile"]
    train = commands["train"]
    preset, run = "experiments/train_paper_v1.toml", "runs/train_paper_v1"
    assert train[3:] == ["train", "--preset", preset, "--seeds", "0,1,2,3,4", "--out", run]
    evaluate = " ".join(commands["evaluate"])
    assert "--trials 50 --workers 2 --plant all" in evaluate
    # every seed's policy in one evaluation (docs/several-seeds.md)
    every = " ".join(f"--policy results/training/seed-{k}/policy.pt" for k in range(5))
    assert f"--scenario-block 0 {every} --out results/evaluation" in evaluate
    assert commands["report"][3:] == ["report", "--in", "results", "--out", "results", "--force"]


def test_quick_writes_elsewhere_and_skips_the_bench() -> None:
    names = [name for name, _ in plan.steps(QUICK)]
    assert names == ["train", "evaluate", "report"]
    assert QUICK.results != FULL.results and QUICK.run != FULL.run


def test_a_run_with_a_checkpoint_is_resumed(tmp_path: Path) -> None:
    setup = replace(QUICK, run=tmp_path / "run", results=tmp_path / "results")
    assert "--resume" not in plan.steps(setup)[0][1]
    (setup.run / "seed-1").mkdir(parents=True)
    (setup.run / "seed-1" / "checkpoint.pt").write_bytes(b"x")
    assert plan.steps(setup)[0][1][-1] == "--resume"  # the others start, seed 1 resumes


def _fake(setup: Setup, codes: dict[str, int]):
    """Steps that are tiny Python commands exiting with ``codes[name]``; 'train' leaves the
    run's files behind as the real one would."""

    def steps(_: Setup) -> list[tuple[str, list[str]]]:
        listed = []
        for name, code in codes.items():
            script = f"import sys; sys.exit({code})"
            if name == "train":
                runs = [plan.seed_run(setup, seed) for seed in setup.seeds]
                for run in runs:
                    run.mkdir(parents=True, exist_ok=True)
                script = (
                    "from pathlib import Path; "
                    + "; ".join(
                        f"Path({str(run / f)!r}).write_text({run.name + f!r})"
                        for run in runs
                        for f in TRAINING_FILES
                    )
                    + f"; import sys; sys.exit({code})"
                )
            listed.append((name, [sys.executable, "-c", script]))
        return listed

    return steps


def codes_script(code: int) -> str:
    return f"import sys; sys.exit({code})"


def test_successful_steps_copy_the_training_files_and_record_each_step(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    setup = replace(QUICK, run=tmp_path / "run", results=tmp_path / "results")
    monkeypatch.setattr(reproduce, "steps", _fake(setup, {"train": 0, "report": 0}))
    records = reproduce.reproduce(setup)
    assert [(r.name, r.returncode) for r in records] == [("train", 0), ("report", 0)]
    for name in TRAINING_FILES:
        assert (setup.results / "training" / name).read_text() == f"seed-0{name}"
        for seed in (0, 1, 2):
            copied = setup.results / "training" / f"seed-{seed}" / name
            assert copied.read_text() == f"seed-{seed}{name}"
    manifest = (setup.results / MANIFEST).read_text()
    assert "training 0,1,2 (training stream" in manifest
    assert "all steps succeeded" in manifest
    assert manifest.count("| 0 |") == 2


def test_a_failing_step_stops_the_run_and_the_manifest_names_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    setup = replace(QUICK, run=tmp_path / "run", results=tmp_path / "results")
    codes = {"train": 0, "evaluate": 3, "report": 0}
    monkeypatch.setattr(reproduce, "steps", _fake(setup, codes))
    records = reproduce.reproduce(setup)
    assert [r.name for r in records] == ["train", "evaluate"]
    assert "failed at evaluate" in (setup.results / MANIFEST).read_text()
    monkeypatch.setattr(reproduce, "QUICK", setup)
    done = runner.invoke(app, ["reproduce", "--quick"])
    assert done.exit_code == 3
    assert done.stderr.strip() == f"error: step evaluate failed: python -c {codes_script(3)}"


def test_results_written_by_a_run_do_not_make_the_commit_dirty(tmp_path: Path) -> None:
    import subprocess

    from pushctl.files.provenance import git_commit

    def git(*args: str) -> None:
        subprocess.run(["git", *args], cwd=tmp_path, check=True, capture_output=True)

    git("init", "-q")
    (tmp_path / "code.py").write_text("a = 1\n")
    (tmp_path / "results").mkdir()
    (tmp_path / "results" / "table.csv").write_text("x\n")
    git("add", ".")
    git("-c", "user.name=t", "-c", "user.email=t@t", "commit", "-qm", "c")
    clean = git_commit(tmp_path)
    assert clean != "unknown" and not clean.endswith("-dirty")
    (tmp_path / "results" / "table.csv").write_text("y\n")
    assert git_commit(tmp_path) == clean
    (tmp_path / "code.py").write_text("a = 2\n")
    assert git_commit(tmp_path) == f"{clean}-dirty"
    assert git_commit(tmp_path.parent / "nowhere") == "unknown"


def test_the_training_seeds_are_an_option(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    setup = replace(QUICK, run=tmp_path / "run", results=tmp_path / "results")
    seen = []
    monkeypatch.setattr(reproduce, "QUICK", setup)
    monkeypatch.setattr(reproduce, "reproduce", lambda chosen: seen.append(chosen) or [])
    assert runner.invoke(app, ["reproduce", "--quick", "--seeds", "4"]).exit_code == 0
    assert seen[0].seeds == (4,)
    assert "--seeds 4 " in " ".join(plan.steps(seen[0])[0][1]) + " "
    refused = runner.invoke(app, ["reproduce", "--quick", "--seeds", "2-0"])
    assert refused.exit_code == 2 and refused.stderr.startswith("error: ")
    assert len(refused.stderr.strip().splitlines()) == 1 and len(seen) == 1


def test_the_manifest_reports_each_stages_time_and_grades_none(tmp_path: Path) -> None:
    setup = replace(FULL, run=tmp_path / "run", results=tmp_path / "results", seeds=(0, 1, 2))
    for seed, seconds in ((0, 900.0), (1, 1500.0)):  # seed 2 recorded no time
        plan.seed_run(setup, seed).mkdir(parents=True)
        (plan.seed_run(setup, seed) / "timing.json").write_text(
            f'{{"seconds": {seconds}, "sessions": 1}}'
        )
    trials = setup.results / "evaluation" / "trials.csv"
    trials.parent.mkdir(parents=True)
    trials.write_text("# made by: test\nobject,plant\n" + "cube,sim\n" * 2400)
    records = [
        plan.StepRecord("train", "pushctl train", 0, 1600.0),
        plan.StepRecord("evaluate", "pushctl evaluate", 0, 400.0),
        plan.StepRecord("report", "pushctl report", 0, 60.0),
    ]
    rows = {row.stage: row for row in manifests.timings(setup, records)}
    assert [rows[f"training, seed {k}"].seconds for k in (0, 1, 2)] == [900.0, 1500.0, None]
    assert rows["evaluation"].note == "2400 pushes"
    assert rows["whole run"].seconds == pytest.approx(2060.0)
    manifests.write_manifest(setup, records, datetime.now(timezone.utc))
    manifest = (setup.results / MANIFEST).read_text()
    assert "| training, seed 0 | 15 min 00.0 s |" in manifest
    assert "budget" not in manifest.lower() and "missed" not in manifest
    cores = len(os.sched_getaffinity(0))
    assert f"3 seeds at once on {cores} cores" in rows["training, seed 0"].note
    # the kind of machine the bytes belong to (docs/reproducibility.md)
    assert f"- machine: {machine_description()} (the bytes repeat" in manifest
    one = replace(setup, seeds=(0,))
    assert "at once" not in manifests.timings(one, records)[0].note
    resumed = [replace(records[0], command="pushctl train --resume"), *records[1:]]
    assert "this invocation only" in manifests.timings(setup, resumed)[-1].note
    assert "this invocation only" not in rows["whole run"].note


@pytest.mark.slow
def test_a_tiny_reproduction_times_every_stage(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, write_tiny_preset
) -> None:
    preset = write_tiny_preset(episodes=2, pd_every=2, validate_every=2)
    setup = Setup(str(preset), tmp_path / "run", 1, tmp_path / "results", bench=False, seeds=(0,))
    monkeypatch.chdir(tmp_path)
    records = reproduce.reproduce(setup)
    assert [(r.name, r.returncode) for r in records] == [
        ("train", 0),
        ("evaluate", 0),
        ("report", 0),
    ]
    rows = {row.stage: row for row in manifests.timings(setup, records)}
    trained = rows["training, seed 0"].seconds
    assert trained is not None and 0.0 < trained < records[0].seconds
    assert rows["evaluation"].seconds is not None
    manifest = (setup.results / MANIFEST).read_text()
    assert "## Timings" in manifest and "budget" not in manifest.lower()
    assert f"preset {preset}" in manifest
    steps = setup.results / "evaluation" / "steps.csv"
    assert gzip.decompress(steps.with_name("steps.csv.gz").read_bytes()) == steps.read_bytes()


def test_the_manifest_names_the_command_that_gave_the_setup() -> None:
    commands = manifests.commands
    assert commands(FULL) == ("make reproduce-tables", "pushctl reproduce")
    assert commands(QUICK) == ("make reproduce-tables QUICK=1", "pushctl reproduce --quick")
    quick_preset = replace(FULL, preset="quick", force=True)
    assert commands(quick_preset) == (
        "make reproduce-tables PRESET=quick FORCE=1",
        "pushctl reproduce --preset quick --force",
    )
    assert commands(replace(FULL, seeds=(0,)))[0] == "make reproduce-tables SEEDS=0"


def test_make_reproduce_tables_runs_the_command_with_the_makefile_s_options() -> None:
    makefile = (Path(__file__).resolve().parents[2] / "Makefile").read_text()
    recipe = makefile.split("\nreproduce-tables:", 1)[1].split("\n\n", 1)[0]
    assert "-m pushctl.cli reproduce" in recipe
    for option in ("--quick", "--force", "--seeds $(SEEDS)", "--preset $(PRESET)"):
        assert option in recipe, option


def test_the_steps_are_compressed_from_this_run_s_file_to_the_same_bytes_each_time(
    tmp_path: Path,
) -> None:
    setup = replace(QUICK, results=tmp_path / "results")
    steps = setup.results / "evaluation" / "steps.csv"
    steps.parent.mkdir(parents=True)
    stale = steps.with_name("steps.csv.gz")
    stale.write_bytes(gzip.compress(b"# made by: an earlier run\n"))
    steps.write_text("# made by: this run\nobject,step\n" + "cube,1\n" * 1000)
    assert reproduce.compress_steps(setup) == stale
    first = stale.read_bytes()
    assert gzip.decompress(first) == steps.read_bytes()
    assert len(first) < steps.stat().st_size / 10
    reproduce.compress_steps(setup)  # no name or time in the header: the same bytes
    assert stale.read_bytes() == first
    assert sorted(p.name for p in steps.parent.iterdir()) == ["steps.csv", "steps.csv.gz"]


def test_every_shipped_file_of_the_reproduction_names_its_commit() -> None:
    """Each file ``make reproduce-tables`` wrote into the shipped ``results/`` (the tables,
    trials, per-step means) names the commit of ``results/provenance.md``, and each training
    curve the commit the manifest says trained the seeds: none is left over from an earlier
    run. (``bench.csv`` is not among them: ``make bench`` rewrites it with its own run's
    commit.)"""
    import re

    results = Path(__file__).resolve().parents[2] / "results"
    manifest = (results / MANIFEST).read_text()
    commit = re.search(r"commit ([0-9a-f]{7,})", manifest)
    trained = re.search(r"- training made at: commit ([0-9a-f]{7,}) \(seeds [0-9,]+\)\n", manifest)
    assert commit is not None and trained is not None  # one commit trained every seed
    made_here = [
        *(results / name for name in ("table3.csv", "table4.csv", "behaviour.csv")),
        results / "evaluation" / "trials.csv",
        results / "evaluation" / "steps.csv.gz",
    ]
    training = sorted((results / "training").rglob("*.csv"))
    for path, made_at in [*((p, commit) for p in made_here), *((p, trained) for p in training)]:
        raw = path.read_bytes()
        head = (gzip.decompress(raw) if path.suffix == ".gz" else raw)[:4000].decode()
        assert head.startswith("# made by:"), path
        assert f"commit {made_at.group(1)}" in head.splitlines()[0], path


def test_the_manifest_gives_the_machine_s_speed_from_this_run_s_bench(tmp_path: Path) -> None:
    setup = replace(FULL, run=tmp_path / "run", results=tmp_path / "results", seeds=(0,))
    setup.results.mkdir()
    (setup.results / "bench.csv").write_text(
        "# made by: test\nname,value,unit,note\n"
        f'{manifests.MJ_STEP_ROW},41.6,us,"MuJoCo, one core"\n'
    )
    started = datetime.now(timezone.utc)
    before_bench = [plan.StepRecord("report", "pushctl report", 0, 10.0)]
    manifests.write_manifest(setup, before_bench, started)  # an earlier run's bench.csv
    assert "this machine's speed" not in (setup.results / MANIFEST).read_text()
    bench = plan.StepRecord("bench", "python -m benchmarks.suite", 0, 60.0)
    manifests.write_manifest(setup, [*before_bench, bench], started)
    manifest = (setup.results / MANIFEST).read_text()
    assert "`mj_step` alone took 41.6 µs in this run's bench" in manifest
    (setup.results / "bench.csv").write_text("name,value\nother,1\n")
    manifests.write_manifest(setup, [*before_bench, bench], started)
    assert "this machine's speed" not in (setup.results / MANIFEST).read_text()


def test_the_manifest_names_the_commit_each_seed_was_trained_at(tmp_path: Path) -> None:
    """A resumed run found finished keeps the commit that trained it: the manifest says so,
    seed by seed, rather than the commit of the evaluation."""
    setup = replace(FULL, run=tmp_path / "run", results=tmp_path / "results", seeds=(0, 1, 2))
    assert manifests.training_commit_lines(setup) == []  # no curves yet
    for seed, commit in ((0, "b09e038"), (1, "b09e038-dirty"), (2, "b09e038")):
        curve = setup.results / "training" / f"seed-{seed}" / "curve.csv"
        curve.parent.mkdir(parents=True)
        curve.write_text(f"# made by: pushctl train; pushctl 0.1.0; commit {commit}; seed {seed}\n")
    assert manifests.training_commit_lines(setup) == [
        "- training made at: commit b09e038 (seeds 0,2); commit b09e038-dirty (seeds 1)"
    ]
    manifests.write_manifest(setup, [], datetime.now(timezone.utc))
    assert (
        "- training made at: commit b09e038 (seeds 0,2)" in (setup.results / MANIFEST).read_text()
    )
