"""The landing study (studies.landing_study): where the prongs landed on the face,
read from a trace, and the fit of force error against it."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from pushctl.episode.landed import spot_offset
from studies.landing_study import landed_summary, landing_fit


def test_a_pd_push_lands_off_the_plans_spot_and_stays_there() -> None:
    """Tuning push 20013 (cube, constant, sim): the object sits about 1 mm across from where
    the plan believes, so the prongs land 1.6 mm across the face from the plan's spot; both
    stick, and the spot is the same at the end of the push."""
    from pushctl.evaluation.tune_feedback import BELIEVED, tuning_env

    env = tuning_env(config=BELIEVED)
    env.reset(options={"object": "cube", "profile": "constant", "scenario_seed": 20013})
    assert env.episode is not None
    trace = env.episode.finish()
    landed = spot_offset(trace, 50)
    assert 1.4e-3 < landed < 1.8e-3
    assert spot_offset(trace, trace.n_steps) == pytest.approx(landed, abs=5e-5)


def test_the_fit_leaves_out_failed_pushes_and_counts_those_on_the_spot() -> None:
    landed = np.array([0.1, -0.3, 1.0, -2.0, 3.0])
    pushes = pd.DataFrame(
        {
            "controller": "law",
            "object": "cube",
            "profile": "constant",
            "landed_mm": landed,
            "force_mN": 5.0 + 10.0 * np.abs(landed),
            "failed": [False, False, False, False, True],
        }
    )
    pushes.loc[4, "force_mN"] = 500.0  # a failed push: not in the fit
    row = landing_fit(pushes).iloc[0]
    assert row["pushes"] == 4 and row["on_spot"] == 2
    assert row["a_mN"] == pytest.approx(5.0) and row["b_mN_per_mm"] == pytest.approx(10.0)
    assert row["correlation"] == pytest.approx(1.0)
    assert row["on_spot_median_mN"] == pytest.approx(5.0 + 10.0 * 0.2)


def test_the_summary_of_an_evaluation_gives_each_group_its_landing_and_force_ratio() -> None:
    across = np.array([1e-3, -2e-3, 0.2e-3, 3e-3])
    trials = pd.DataFrame(
        {
            "plant": "sim",
            "object": "cube",
            "profile": "chirp",
            "controller": ["pd", "pd", "pd", "pd"],
            "placement_across": across,
            "landed_offset": -across,
            "force_error": [0.02, 0.02, 0.02, 0.02],
            "force_error_landed": [0.01, 0.01, 0.01, 0.01],
        }
    )
    (row,) = landed_summary(trials).to_dict("records")
    assert row["landed_mm"] == pytest.approx(1.55)
    assert row["off_spot_share"] == 0.75  # 0.2 mm is on the spot
    assert row["r_placement"] == pytest.approx(1.0)
    assert row["landed_over_plan_spot"] == pytest.approx(0.5)


def test_the_relanding_table_counts_failed_pushes_per_object_in_controller_order() -> None:
    from studies.landing_study import RELANDING_CONTROLLERS, relanding_table

    rows = []
    for obj in ("wedge", "cube"):
        for controller in reversed(RELANDING_CONTROLLERS):
            for i in range(2):
                rows.append(
                    {
                        "controller": controller,
                        "object": obj,
                        "translation_pct": 1.0 + i,
                        "angle_pct": 10.0 * (1 + i),
                        "force_mN": 20.0,
                        "failed": controller == "PD-only" and i == 1,
                    }
                )
    table = relanding_table(pd.DataFrame(rows))
    assert table["object"].tolist() == ["cube"] * 3 + ["wedge"] * 3
    assert table["controller"].tolist() == list(RELANDING_CONTROLLERS) * 2
    assert table["translation_pct"].tolist() == [1.5] * 6
    assert table["angle_pct"].tolist() == [15.0] * 6
    assert table["failed"].tolist() == [1, 0, 0] * 2
    assert table["pushes"].tolist() == [2] * 6


def test_the_relanding_study_pushes_pd_only_from_where_the_approach_landed(monkeypatch) -> None:
    """One tuning push, three ways: PD-only is the push of the approach's landing (the same
    metrics as a `believed` environment's own PD push); the law's two pushes differ, since
    re-landing moves the prongs before the push."""
    from pushctl.episode.metrics import compute_metrics
    from pushctl.evaluation.tune_feedback import BELIEVED, tuning_env
    from studies import landing_study

    monkeypatch.setattr(landing_study, "OBJECT_NAMES", ("wedge",))
    monkeypatch.setattr(landing_study, "PROFILE_NAMES", ("constant",))
    pushes = landing_study.relanding_pushes("sim", 20000, 1)
    assert pushes["controller"].tolist() == [
        "law, approach's landing", "PD-only", "law, re-landed",
    ]  # fmt: skip
    assert set(pushes["seed"]) == {20000}
    env = tuning_env(config=BELIEVED)
    env.reset(options={"object": "wedge", "profile": "constant", "scenario_seed": 20000})
    assert env.episode is not None
    expected = compute_metrics(env.episode.finish())
    pd_only = pushes.iloc[1]
    assert pd_only["translation_pct"] == expected.translation_error_pct
    assert pd_only["angle_pct"] == expected.angle_error_pct
    law = pushes.set_index("controller")["force_mN"]
    assert law["law, approach's landing"] != law["law, re-landed"]
