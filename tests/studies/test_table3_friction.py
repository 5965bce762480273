"""The friction study of Table III: the worlds its episodes build get the model asked for
(and only while asked), and its table counts ratios and failed pushes per model and cell."""

from __future__ import annotations

import pandas as pd
import pytest

import pushctl.episode.runner as runner
from studies.table3_friction import markdown, table, world_friction


def test_the_episodes_worlds_get_the_friction_model_asked_for():
    original = runner.make_world
    with world_friction("polygon", 16):
        world = runner.make_world("cube", arm=None)
        assert (world.config.friction_model, world.config.facets) == ("polygon", 16)
    assert runner.make_world is original
    assert original("cube", arm=None).config.friction_model == "slip_box"


def _rows() -> pd.DataFrame:
    rows = []
    for model, scale in (("slip_box", 1.0), ("polygon", 2.0)):
        for trial in range(4):
            for controller, translation, angle in (("pd", 1.0 + trial, 10.0 + 5 * trial),
                                                   ("feedback", 0.5, 2.0)):  # fmt: skip
                rows.append({"friction_model": model, "object": "cube", "profile": "chirp",
                             "controller": controller, "trial": trial,
                             "translation_error_pct": scale * translation,
                             "angle_error_pct": angle})  # fmt: skip
    return pd.DataFrame(rows)


def test_the_table_has_ratios_failed_pushes_and_paired_differences():
    summary = table(_rows()).set_index("friction_model")
    box, polygon = summary.loc["slip_box"], summary.loc["polygon"]
    assert box["translation_law_pd"] == pytest.approx(0.5 / 2.5)
    assert polygon["translation_law_pd"] == pytest.approx(0.5 / 2.5)
    # PD fails on angle at 25 % (trial 3), on translation above 3 % (box: 3; polygon: 1-3)
    assert (box["failed_pd"], polygon["failed_pd"], box["failed_law"]) == (1, 3, 0)
    assert box["angle_law_minus_pd"] == pytest.approx(2.0 - 17.5)
    assert "| cube | chirp | polygon |" in markdown(summary.reset_index())
