"""``make reproduce-tables``'s runner: the commands it types, resuming a run, copying the
training files, and a manifest written whether the steps succeed or fail."""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import pytest

from pushctl import reproduce
from pushctl.reproduce import FULL, MANIFEST, QUICK, TRAINING_FILES, Setup


def test_the_full_setup_is_the_issue_s_protocol(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)  # no runs/paper here: a fresh run
    commands = {name: argv for name, argv in reproduce.steps(FULL)}
    assert list(commands) == ["train", "evaluate", "report", "bench"]
    train = commands["train"]
    assert train[3:] == ["train", "--preset", "paper", "--seed", "0", "--out", "runs/paper"]
    evaluate = " ".join(commands["evaluate"])
    assert "--trials 50 --workers 2 --plant all" in evaluate
    assert "--policy results/training/policy.pt --out results/evaluation" in evaluate
    assert commands["report"][3:] == ["report", "--in", "results", "--out", "results", "--force"]


def test_quick_writes_elsewhere_and_skips_the_bench() -> None:
    names = [name for name, _ in reproduce.steps(QUICK)]
    assert names == ["train", "evaluate", "report"]
    assert QUICK.results != FULL.results and QUICK.run != FULL.run


def test_a_run_with_a_checkpoint_is_resumed(tmp_path: Path) -> None:
    setup = replace(QUICK, run=tmp_path / "run", results=tmp_path / "results")
    assert "--resume" not in reproduce.steps(setup)[0][1]
    setup.run.mkdir()
    (setup.run / "checkpoint.pt").write_bytes(b"x")
    assert reproduce.steps(setup)[0][1][-1] == "--resume"


def _fake(setup: Setup, codes: dict[str, int]):
    """Steps that are tiny Python commands exiting with ``codes[name]``; 'train' leaves the
    run's files behind as the real one would."""

    def steps(_: Setup) -> list[tuple[str, list[str]]]:
        listed = []
        for name, code in codes.items():
            script = f"import sys; sys.exit({code})"
            if name == "train":
                setup.run.mkdir(parents=True, exist_ok=True)
                script = (
                    "from pathlib import Path; "
                    + "; ".join(
                        f"Path({str(setup.run / f)!r}).write_text({f!r})" for f in TRAINING_FILES
                    )
                    + f"; import sys; sys.exit({code})"
                )
            listed.append((name, [sys.executable, "-c", script]))
        return listed

    return steps


def test_successful_steps_copy_the_training_files_and_record_each_step(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    setup = replace(QUICK, run=tmp_path / "run", results=tmp_path / "results")
    monkeypatch.setattr(reproduce, "steps", _fake(setup, {"train": 0, "report": 0}))
    records = reproduce.reproduce(setup)
    assert [(r.name, r.returncode) for r in records] == [("train", 0), ("report", 0)]
    for name in TRAINING_FILES:
        assert (setup.results / "training" / name).read_text() == name
    manifest = (setup.results / MANIFEST).read_text()
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
    assert reproduce.main(["--quick"]) == 3


def test_results_written_by_a_run_do_not_make_the_commit_dirty(tmp_path: Path) -> None:
    import subprocess

    from pushctl.provenance import git_commit

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
