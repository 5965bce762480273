"""The catch-up law's search (studies.catchup_search) without pushing: its
candidates, the refinement's neighbours, the summary's ratios on a synthetic rows file, and
the gains file it writes."""

from __future__ import annotations

import math
from pathlib import Path

import pandas as pd
import pytest

from pushctl.control.feedback import load_feedback_gains
from studies import catchup_search as search


def test_the_candidates_are_fixed_named_and_keep_the_steady_law_after_the_phase() -> None:
    first, again = search.candidates(), search.candidates()
    assert list(first) == list(again) and len(first) == 3 + search.N_RANDOM
    steady = first["steady"]
    assert steady.catchup_time == 0.0 and not steady.owns_gate
    hand = first["hand"]
    assert (hand.catchup_time, hand.catchup_k, hand.catchup_lateral_ratio) == (3.0, 3.0, 0.15)
    for gains in first.values():
        assert (gains.k, gains.k_i, gains.lateral_ratio) == (steady.k, steady.k_i, 0.05)


def test_the_refinement_moves_one_parameter_at_a_time() -> None:
    centre = (2.0, 5.0, 0.25, 0.4, 1.5e-4, None)
    moved = search.neighbours(centre)
    assert len(moved) == 10
    for point in moved.values():
        assert sum(a != b for a, b in zip(point, centre, strict=True)) == 1
    assert "T2_k5_c0.25_F0.4_g0" in moved and "T2_k5_c0.25_F0.4_g0.15_w0.05" in moved
    turn_kept = search.point_gains(load_feedback_gains(), moved["T2_k5_c0.25_F0.4_g0.15_w0.05"])
    assert (turn_kept.catchup_lateral_ratio, turn_kept.catchup_turn_ratio) == (0.25, 0.05)


def _rows(tmp_path: Path) -> Path:
    """Two pushes per cell of one plant: steady at 1 % and 2 %, 'hand' at half of it."""
    rows = []
    for name, factor in (("steady", 1.0), ("hand", 0.5)):
        for case, (obj, profile) in enumerate((("cube", "constant"), ("wedge", "chirp"))):
            for i in range(2):
                seed = case * search.PER_CASE + i
                value = (i + 1) * factor
                rows.append((name, "sim", obj, profile, seed, value, 10 * value, 0))
    path = tmp_path / "sim.csv"
    pd.DataFrame(rows, columns=search.COLUMNS).to_csv(path, index=False)
    return path


def test_the_summary_scores_the_objective_and_per_cell_ratios(tmp_path: Path) -> None:
    found = search.summary([_rows(tmp_path), tmp_path / "absent.csv"])
    assert found["steady"]["objective"] == pytest.approx(1.5 + 15.0)
    hand = found["hand"]
    assert hand["objective"] == pytest.approx(0.75 + 7.5) and hand["pushes"] == 4
    assert hand["sim/wedge/chirp"] == (0.5, 0.5)
    only_first = search.summary([tmp_path / "sim.csv"], per_case=1)
    assert only_first["steady"]["objective"] == pytest.approx(1.0 + 10.0)


def test_a_failed_push_makes_the_objective_infinite(tmp_path: Path) -> None:
    path = _rows(tmp_path)
    rows = pd.read_csv(path)
    rows.loc[rows.index[-1], ["translation_error_pct", "angle_error_pct", "failed"]] = (
        math.nan,
        math.nan,
        1,
    )
    rows.to_csv(path, index=False)
    assert search.summary([path])["hand"]["objective"] == math.inf


def test_the_written_file_loads_as_the_candidates_gains(tmp_path: Path) -> None:
    found = search.summary([_rows(tmp_path)])
    text = search.catchup_toml("hand", found, "python -m studies.catchup_search")
    path = tmp_path / "catchup.toml"
    path.write_text(text)
    assert load_feedback_gains(path) == search.candidates()["hand"]
    assert 'candidate = "hand"' in text and 'stream = "tuning"' in text
