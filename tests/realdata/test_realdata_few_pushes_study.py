"""The few-pushes study (``studies.realdata_few_pushes``): each held-out shape starts from its
fold's parameters, is refined on K of its calibration pushes only, and is scored on the
rest of its pushes."""

from __future__ import annotations

from pushctl.realdata.fit import FitGrids
from pushctl.realdata.loso import run_loso
from pushctl.realdata.replay import ReplaySettings
from studies.realdata_few_pushes import few_pushes_scores

GRIDS = FitGrids(mu_contact=(0.1, 0.3), rim_weight=(0.0, 4.0), mu_ground=(0.3,))


def test_held_out_shapes_are_refined_on_k_pushes_and_scored_on_the_rest(synthetic_data):
    settings = ReplaySettings()
    loso = run_loso(synthetic_data, 0, settings, GRIDS).table
    table = few_pushes_scores(synthetic_data, loso, 1, 0, settings, GRIDS).set_index("shape")
    assert list(table.index) == ["square", "tri", "all"]
    assert (table.loc[["square", "tri"], "felt_pushes"] == 1).all()
    assert list(table.loc[["square", "tri"], "n"]) == [7, 7]  # 8 pushes, 1 used to fit
    assert table.loc["all", "n"] == 14
    assert (
        table.loc[["square", "tri"], "felt_rim_weight"].isin([-1.0, 0.0, 1.0, 3.0, 4.0, 5.0]).all()
    )
