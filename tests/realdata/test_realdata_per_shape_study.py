"""Zhou's protocol study (``studies.realdata_per_shape``): one fit per shape and surface on
the calibration split, each test push scored with its own group's fit."""

from __future__ import annotations

import pytest

from pushctl.realdata.fit import FitGrids
from pushctl.realdata.replay import ReplaySettings
from studies.realdata_per_shape import markdown, per_shape_scores

GRIDS = FitGrids(mu_contact=(0.1, 0.3), rim_weight=(0.0,), mu_ground=(0.3,))


def test_each_shape_gets_its_own_fit_and_the_test_split_is_scored(synthetic_data):
    table = per_shape_scores(synthetic_data, 0, ReplaySettings(), GRIDS)
    groups = table[table["surface"] != "all"]
    assert sorted(groups["shape"]) == ["square", "tri"]
    # 8 pushes a group, 2 (20 %, rounded up) for calibration: 6 test pushes each
    assert list(groups["n"]) == [6, 6]
    # near the truth the pushes were simulated with (0.3), from two noisy pushes each
    assert groups["mu_contact"].between(0.25, 0.35).all()
    total = table[table["surface"] == "all"].iloc[0]
    assert total["nmse"] == pytest.approx(groups["nmse"].mean())
    assert total["nmse"] < 0.2 and "| felt | tri |" in markdown(table)


def test_a_refined_fit_is_no_worse_than_its_start_on_the_calibration_pushes(synthetic_data):
    from pushctl.realdata.data import calibration_mask, load_pushes
    from pushctl.realdata.fit import ReplayCache
    from pushctl.realdata.metrics import group_scores
    from pushctl.realdata.replay import SurfaceParameters
    from studies.realdata_per_shape import refine

    data = load_pushes(synthetic_data)
    pushes = data.pushes[calibration_mask(data.pushes, 0) & (data.pushes["shape"] == "tri")]
    pushes = pushes.reset_index(drop=True)
    cache = ReplayCache(data.shapes, ReplaySettings())
    start = SurfaceParameters(mu_contact=0.1, mu_ground=0.3, rim_weight=4.0)
    fit = refine(pushes, "felt", start, GRIDS, cache)
    at_start = float(group_scores(pushes, cache.ends(pushes, "felt", start))["nmse"].mean())
    assert fit["calibration_nmse"] <= at_start
    assert fit["parameters"] != start
