"""``pushctl tune-feedback``: the search scores PD-only and the grid on the tuning stream and
writes a gains file that loads, with its provenance and every candidate."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from pushctl.cli import app
from pushctl.control.feedback import load_feedback_gains
from pushctl.evaluation.tune_feedback import GRID
from pushctl.files.toml import read_toml

runner = CliRunner()


@pytest.mark.slow  # ~30 candidates × 6 pushes of 2 s: about a minute
def test_the_search_writes_a_gains_file_with_its_record(tmp_path: Path) -> None:
    out = tmp_path / "gains.toml"
    result = runner.invoke(
        app, ["tune-feedback", "--per-case", "1", "--duration", "2", "--out", str(out)]
    )
    assert result.exit_code == 0, result.output
    text = out.read_text()
    assert text.startswith("# made by: pushctl tune-feedback --first-scenario 0 --per-case 1")
    gains = load_feedback_gains(out)
    search = read_toml(out, "gains")["search"]
    assert search["stream"] == "tuning" and search["residual_path"] == "reference"
    assert search["plants"] == ["sim", "proxy"] and gains.turn_ratio == 0.05
    assert gains.smoothing == 0.1
    candidates = search["candidates_k_ki_objective_translation_angle"]
    assert len(candidates) >= len(GRID["k"]) * len(GRID["k_i"])
    best = min(candidates, key=lambda c: c[2])
    assert [gains.k, gains.k_i] == best[:2]
    assert search["best_objective"] == best[2]
    assert "PD-only" in result.output and f"wrote {out}" in result.output.replace("\n", "")


def test_a_bad_output_is_one_line_and_nothing_runs(tmp_path: Path) -> None:
    result = runner.invoke(app, ["tune-feedback", "--out", str(tmp_path / "gains.txt")])
    assert result.exit_code == 2
    assert "--out" in result.output and ".toml" in result.output
    fresh = ["--out", str(tmp_path / "fresh.toml")]
    result = runner.invoke(app, ["tune-feedback", "--per-case", "0", "--duration", "2", *fresh])
    assert result.exit_code == 2 and "--per-case must be an integer >= 1" in result.output
    result = runner.invoke(app, ["tune-feedback", "--plant", "real", *fresh])
    assert result.exit_code == 2 and "--plant must be one of sim, proxy, both" in result.output
    assert not (tmp_path / "fresh.toml").exists()


def test_an_existing_gains_file_is_refused_before_the_search(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "gains.toml"
    out.write_text("# hand-tuned, keep\n")
    result = runner.invoke(app, ["tune-feedback", "--per-case", "1", "--out", str(out)])
    assert result.exit_code == 2 and "--force" in result.output and str(out) in result.output
    assert out.read_text() == "# hand-tuned, keep\n"
    # the default output is the working directory's experiments/, never the shipped defaults
    monkeypatch.chdir(tmp_path)
    (tmp_path / "experiments").mkdir()
    (tmp_path / "experiments" / "feedback_gains.toml").write_text("# mine\n")
    default = runner.invoke(app, ["tune-feedback", "--per-case", "1"])
    assert default.exit_code == 2 and "experiments/feedback_gains.toml" in default.output
