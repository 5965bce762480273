"""``pushctl realdata`` end to end on the synthetic data: fit, score (all shapes and a shape
left out of the fit), logs; bad input is one line and exit code 2; results are not
overwritten."""

from __future__ import annotations

import pandas as pd
import pytest
import tomllib
from typer.testing import CliRunner

from pushctl.cli import app

runner = CliRunner()


@pytest.fixture(scope="module")
def fitted(synthetic_data, tmp_path_factory):
    out = tmp_path_factory.mktemp("fit") / "fit.toml"
    result = runner.invoke(app, ["realdata", "fit", "--data", str(synthetic_data),
                                 "--out", str(out), "--workers", "1"])  # fmt: skip
    assert result.exit_code == 0, result.output
    return out


def test_fit_writes_a_recorded_toml(fitted):
    text = fitted.read_text()
    assert text.startswith("# made by: pushctl realdata fit")
    assert "[surface.felt]" in text and "mu_contact" in text and "calibration_digest" in text


def test_score_writes_predictions_summary_and_figures(synthetic_data, fitted, tmp_path):
    out = tmp_path / "score"
    result = runner.invoke(app, ["realdata", "score", "--data", str(synthetic_data),
                                 "--friction", str(fitted), "--out", str(out),
                                 "--workers", "1"])  # fmt: skip
    assert result.exit_code == 0, result.output
    predictions = pd.read_csv(out / "predictions.csv", comment="#")
    assert list(predictions.columns) == ["push_id", "x1", "y1", "theta1"]
    assert len(predictions) == 16
    summary = pd.read_csv(out / "summary.csv", comment="#")
    test_total = summary[(summary.split == "test") & (summary.surface == "all")].iloc[0]
    assert test_total["n"] == 12
    assert test_total["nmse"] < 0.1 and "zhou_nmse" in summary.columns
    assert (out / "displacement.png").stat().st_size > 0 and (out / "examples.png").exists()
    again = runner.invoke(app, ["realdata", "score", "--data", str(synthetic_data),
                                "--friction", str(fitted), "--out", str(out)])  # fmt: skip
    assert again.exit_code == 2 and again.output.startswith("error: --out")
    assert len(again.output.strip().splitlines()) == 1


def test_leave_one_shape_out(synthetic_data, tmp_path):
    fit = tmp_path / "loso.toml"
    result = runner.invoke(app, ["realdata", "fit", "--data", str(synthetic_data), "--out",
                                 str(fit), "--exclude-shape", "tri", "--workers", "1"])  # fmt: skip
    assert result.exit_code == 0, result.output
    out = tmp_path / "tri"
    result = runner.invoke(app, ["realdata", "score", "--data", str(synthetic_data), "--friction",
                                 str(fit), "--out", str(out), "--shapes", "tri"])  # fmt: skip
    assert result.exit_code == 0, result.output
    summary = pd.read_csv(out / "summary.csv", comment="#")
    assert set(summary["shape"]) == {"tri", "all"}
    assert summary[summary.split == "test"]["n"].iloc[0] == 8  # all of tri is unseen


def test_the_fit_searches_the_rim_weights_it_is_given(synthetic_data, tmp_path):
    out = tmp_path / "fit.toml"
    result = runner.invoke(app, ["realdata", "fit", "--data", str(synthetic_data), "--out",
                                 str(out), "--rim-weights", "7", "--workers", "1"])  # fmt: skip
    assert result.exit_code == 0, result.output
    rim = tomllib.loads(out.read_text())["surface"]["felt"]["rim_weight"]
    assert rim in (6.0, 7.0, 8.0)  # the grid's one value, then +-1 around it


def test_logs_replay(synthetic_data, tmp_path):
    result = runner.invoke(app, ["realdata", "logs", "--data", str(synthetic_data),
                                 "--out", str(tmp_path / "logs")])  # fmt: skip
    assert result.exit_code == 0, result.output
    table = pd.read_csv(tmp_path / "logs" / "segments.csv", comment="#")
    assert len(table) == 4 and (tmp_path / "logs" / "paths.png").exists()


@pytest.mark.parametrize(
    "args, message",
    [
        (["fit", "--data", "/nonexistent", "--out", "{tmp}/f.toml"], "not a directory"),
        (["fit", "--data", "{data}", "--out", "{tmp}/f.txt"], ".toml"),
        (["fit", "--data", "{data}", "--out", "{tmp}/f.toml", "--exclude-shape", "x"], "x"),
        (["fit", "--data", "{data}", "--out", "{tmp}/f.toml", "--rim-weights", "0,a"],
         "--rim-weights"),
        (["loso", "--data", "{data}", "--out", "{tmp}/o", "--rim-weights", "40"], "rim_weight"),
        (["fit", "--data", "{data}", "--out", "{tmp}/f.toml", "--facets", "6"],
         "facets must be a multiple of 4"),
        (["loso", "--data", "{data}", "--out", "{tmp}/o", "--friction-model", "disc"],
         "friction_model must be one of"),
        (["logs", "--data", "{data}", "--out", "{tmp}/o", "--facets", "10"],
         "facets must be a multiple of 4"),
        (["score", "--data", "{data}", "--friction", "{tmp}/none.toml", "--out", "{tmp}/o"],
         "does not exist"),
        (["score", "--data", "{data}", "--friction", "{data}/mit/shapes.csv", "--out",
          "{tmp}/o"], "not valid TOML"),
        (["score", "--data", "{data}", "--friction", "{tmp}/abs.toml", "--out", "{tmp}/o"],
         "no parameters for surface(s) felt of the data"),
    ],
)  # fmt: skip
def test_bad_input_is_one_line_and_exit_2(args, message, synthetic_data, tmp_path):
    args = [a.format(data=synthetic_data, tmp=tmp_path) for a in args]
    (tmp_path / "abs.toml").write_text("[surface.abs]\nmu_contact = 0.2\nmu_ground = 0.3\n")
    result = runner.invoke(app, ["realdata", *args])
    assert result.exit_code == 2
    assert result.output.startswith("error:") and message in result.output
    assert len(result.output.strip().splitlines()) == 1 and "['" not in result.output
    assert not (tmp_path / "o").exists()
