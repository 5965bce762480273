"""Fitting the two-finger logs leaving one start out: a start's parameters come from the
other starts only (changing its own logs does not change them), every segment is scored
once, a setup with one start is refused, and ``logs --fit`` writes what it used."""

from __future__ import annotations

import shutil

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from pushctl.cli import app
from pushctl.errors import ConfigError
from pushctl.realdata.logfit import LogGrids, fit_logs
from pushctl.realdata.logs import read_segments

runner = CliRunner()
GRIDS = LogGrids(mu_contact=(0.1, 0.6), rim_weight=(0.0, 4.0))


def _two_starts(synthetic_data, root, slide_b: float = 0.0):
    """The synthetic logs as two starts of one setup; start ``b``'s recorded object drifts
    ``slide_b`` mm sideways per row (so that its best parameters may differ)."""
    source = synthetic_data / "two_finger_logs" / "rect_flat" / "rect_0_0_0"
    for start in ("a", "b"):
        target = root / "two_finger_logs" / "rect_flat" / start
        shutil.copytree(source, target)
    for log in sorted((root / "two_finger_logs" / "rect_flat" / "b").glob("log*.txt")):
        table = np.loadtxt(log, delimiter=",")
        moving = np.any(table[:, 1:4] != 0, axis=1)
        table[moving, 2] += slide_b * np.arange(moving.sum())
        np.savetxt(log, table, delimiter=",", fmt="%.4f")
    return root


def test_a_start_is_fitted_on_the_other_starts_only(synthetic_data, tmp_path):
    plain = read_segments(_two_starts(synthetic_data, tmp_path / "plain"))
    moved = read_segments(_two_starts(synthetic_data, tmp_path / "moved", slide_b=0.3))
    first = fit_logs(plain, "polygon", GRIDS).table
    second = fit_logs(moved, "polygon", GRIDS).table
    own_b = first["start"] == "b"
    # b's parameters come from a, which did not change
    assert first.loc[own_b, ["mu_contact", "rim_weight"]].equals(
        second.loc[own_b, ["mu_contact", "rim_weight"]]
    )
    # ... while a's, fitted on b, do: the drift is informative enough to move a fit
    assert not first.loc[~own_b, ["rim_weight"]].equals(second.loc[~own_b, ["rim_weight"]])
    assert len(first) == len(plain) and first["mu_contact"].isin(GRIDS.mu_contact).all()
    assert (first["end_position_error_mm"] >= 0).all()


def test_a_setup_with_one_start_is_refused(synthetic_data):
    with pytest.raises(ConfigError, match="one start"):
        fit_logs(read_segments(synthetic_data), "polygon", GRIDS)


def test_logs_fit_writes_the_parameters_it_replayed_with(synthetic_data, tmp_path):
    data = _two_starts(synthetic_data, tmp_path / "data")
    out = tmp_path / "out"
    args = ["realdata", "logs", "--data", str(data), "--out", str(out), "--fit"]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    table = pd.read_csv(out / "segments.csv", comment="#")
    assert {"mu_contact", "rim_weight", "within_3x_floor"} <= set(table.columns)
    assert set(table["start"]) == {"a", "b"} and (out / "paths.png").exists()
