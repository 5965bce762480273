"""``python -m benchmarks.compare_commits step``: its child script and its arguments."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from benchmarks.commits.step import _CHILD, METRICS, main, unpack
from pushctl import native


def test_the_child_script_compiles_and_reports_every_metric() -> None:
    compile(_CHILD, "<bench child>", "exec")
    for metric in METRICS:
        if metric != "cold MLCP, ProxQP path of the reference":  # derived by the parent
            assert f'"{metric}"' in _CHILD, metric


def test_a_core_the_machine_lacks_is_a_one_line_error(capsys) -> None:
    assert main(["--against", "HEAD", "--core", "4096", "--repeats", "1"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: --core must be a core of this machine") and err.count("\n") == 1


def test_the_ratio_is_the_median_of_the_pairs_so_a_drift_between_pairs_cancels() -> None:
    """Both trees equally fast; the machine twice as slow for the last pairs, and for one
    child of the third: the trees' medians (20 against 10) compare slow children with fast
    ones, each pair's ratio is 1 but that one."""
    import statistics

    from benchmarks.commits.step import paired_ratio

    this = [10.0, 10.0, 20.0, 20.0, 20.0]
    reference = [10.0, 10.0, 10.0, 20.0, 20.0]
    assert statistics.median(this) / statistics.median(reference) == 2.0
    assert paired_ratio(this, reference) == 1.0
    assert paired_ratio([9.0, 18.0, 27.0], [10.0, 20.0, 30.0]) == 0.9


def _runs_compiled(tree: Path) -> bool:
    """Whether pushctl at ``tree`` loads its compiled library, in a fresh process."""
    done = subprocess.run(
        [sys.executable, "-c", "from pushctl import native; print(native.available())"],
        env={**os.environ, "PYTHONPATH": str(tree)},
        cwd=tree,
        capture_output=True,
        text=True,
        check=True,
    )
    return done.stdout.strip() == "True"


def test_an_unpacked_reference_runs_with_the_compiled_library_it_had(tmp_path: Path) -> None:
    """git archive leaves the built library out: a reference with the library's sources
    (here this checkout's own last commit) gets this tree's copy where its sources are the
    same, so it is timed as it ran."""
    if not native.available():
        pytest.skip("this tree runs without its compiled library")
    root = Path(__file__).resolve().parents[2]
    known = subprocess.run(["git", "-C", str(root), "cat-file", "-e", "HEAD^{commit}"], check=False)
    if known.returncode != 0:
        pytest.skip("not a git checkout")
    assert _runs_compiled(unpack("HEAD", tmp_path))


def test_it_refuses_an_unknown_commit_and_an_existing_csv(
    tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    out = tmp_path / "compare.csv"
    out.write_text("shipped\n")
    assert main(["--against", "HEAD", "--out", str(out), "--repeats", "1"]) == 2
    assert "--force" in capsys.readouterr().err and out.read_text() == "shipped\n"
    assert main(["--against", "no-such-commit", "--repeats", "1"]) == 2
    error = capsys.readouterr().err.strip()
    assert error.startswith("error: --against no-such-commit") and len(error.splitlines()) == 1
