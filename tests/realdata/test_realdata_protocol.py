"""The protocol's pieces: the split, the scores, the fit recovering known parameters, the
logs' segments, and a small replay of the recorded pushes."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from pushctl.errors import ConfigError
from pushctl.realdata.data import calibration_mask, load_pushes
from pushctl.realdata.fit import fit_surfaces
from pushctl.realdata.logs import read_segments, replay_segment, score_segments
from pushctl.realdata.metrics import group_scores, overall, recorded
from pushctl.realdata.replay import ReplaySettings, SurfaceParameters, replay_pushes


def test_the_split_takes_a_fifth_of_each_group_and_follows_the_seed(synthetic_data):
    pushes = load_pushes(synthetic_data).pushes
    mask = calibration_mask(pushes, seed=3)
    assert mask.sum() == 4  # ceil(0.2 * 8) per shape
    assert (pushes[mask].groupby("shape").size() == 2).all()
    assert np.array_equal(mask, calibration_mask(pushes.iloc[::-1].reset_index(drop=True),
                                                 3)[::-1])  # fmt: skip
    assert not np.array_equal(mask, calibration_mask(pushes, seed=4))


def test_scores_are_zero_for_the_truth_and_one_for_no_motion(synthetic_data):
    pushes = load_pushes(synthetic_data).pushes
    truth = pushes[["x1", "y1", "theta1"]].to_numpy()
    assert overall(group_scores(pushes, truth))["nmse"] == 0.0
    still = pushes[["x0", "y0", "theta0"]].to_numpy()
    d = recorded(pushes)
    by_hand = np.mean([(d[g] ** 2).mean(0) / d[g].var(0) for g in (slice(0, 8), slice(8, 16))])
    assert overall(group_scores(pushes, still))["nmse"] == pytest.approx(by_hand)


def test_the_fit_recovers_the_contact_friction_it_was_made_with(synthetic_data):
    data = load_pushes(synthetic_data)
    fits = fit_surfaces(data.pushes, data.shapes, ReplaySettings())
    assert fits["felt"]["parameters"].mu_contact == pytest.approx(0.3, abs=0.051)
    assert fits["felt"]["calibration_nmse"] < 0.05


def test_bad_files_raise_one_line_errors(tmp_path, synthetic_data):
    with pytest.raises(ConfigError, match="not a directory"):
        load_pushes(tmp_path / "missing")
    (tmp_path / "mit").mkdir()
    pushes = pd.read_csv(synthetic_data / "mit" / "pushes.csv").drop(columns="tip_x1")
    pushes.to_csv(tmp_path / "mit" / "pushes.csv", index=False)
    (tmp_path / "mit" / "shapes.csv").write_text((synthetic_data / "mit/shapes.csv").read_text())
    with pytest.raises(ConfigError, match="missing columns"):
        load_pushes(tmp_path)


def test_log_segments_split_at_lifts_and_drop_vision_dropouts(synthetic_data):
    segments = read_segments(synthetic_data)
    assert len(segments) == 4 and {s.index for s in segments} == {0, 1}
    assert all(len(s.t) == 40 - (s.index == 0) for s in segments)
    assert all(np.all(s.object[:, 0] != 0) or s.index == 0 for s in segments)
    from pushctl.kinematic import Friction, PressurePrior

    replays = [replay_segment(s, Friction(0.3, 0.3, "polygon"), PressurePrior()) for s in segments]
    table = score_segments(segments, replays)
    assert (table["path_rmse_mm"] < 3.0).all()
    assert (table["repeats"] == 2).all()


def test_a_small_replay_of_the_recorded_pushes_beats_no_motion(real_data):
    data = load_pushes(real_data)
    pushes = data.pushes.groupby(["surface", "shape"]).head(3).reset_index(drop=True)
    params = {s: SurfaceParameters(0.25) for s in ("abs", "plywood")}
    ends = replay_pushes(pushes, data.shapes, params, ReplaySettings())
    ours = overall(group_scores(pushes, ends))
    still = overall(group_scores(pushes, pushes[["x0", "y0", "theta0"]].to_numpy()))
    assert ours["position_error_mm"] < 0.5 * still["position_error_mm"]


def test_the_recorded_logs_replay_within_centimetres(real_data):
    from pushctl.kinematic import Friction, PressurePrior

    segment = read_segments(real_data)[0]
    replay = replay_segment(segment, Friction(0.3, 0.3, "polygon"), PressurePrior())
    table = score_segments([segment], [replay])
    assert table["path_rmse_mm"].iloc[0] < 10.0
