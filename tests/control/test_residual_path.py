"""The residual paths in the episode (pushctl.control.residual, Episode.step): without a
residual both are PD-only to the bit; a residual moves the reference on one and not the
other; and the pose a controller reads (Episode.measured_pose) is the trace's camera pose
on the proxy, the true pose on the simulator."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pushctl.control.gains import load_gains
from pushctl.episode.proxy import ProxyEffects
from pushctl.episode.runner import Episode
from pushctl.episode.scenario import Scenario
from pushctl.errors import ConfigError
from pushctl.types import PlanarPose

GAINS = load_gains()
TURNING_GOAL = PlanarPose(0.62, 0.02, math.radians(20.0))


def _scenario() -> Scenario:
    return Scenario(object="cube", profile="trapezoid", goal=TURNING_GOAL, duration=2.0, seed=3)


def test_without_a_residual_both_paths_push_as_pd_only() -> None:
    frames = [
        Episode(_scenario(), GAINS, residual_path=path).run().to_frame().to_numpy()
        for path in ("reference", "velocity")
    ]
    assert frames[0].tobytes() == frames[1].tobytes()


def test_the_reference_path_accumulates_the_twist_and_the_velocity_path_does_not() -> None:
    residual = np.array([1e-3, -2e-3, 0.01])
    for path, expected in (("reference", 50 * 0.01 * residual), ("velocity", np.zeros(3))):
        episode = Episode(_scenario(), GAINS, residual_path=path)
        episode.reset()
        for _ in range(50):
            episode.step(residual)
        np.testing.assert_allclose(episode.reference_offset, expected, rtol=1e-12, atol=0)
        episode.reset()  # a new push starts from the plan
        np.testing.assert_array_equal(episode.reference_offset, np.zeros(3))


def test_the_offset_limit_clips_each_component_and_the_reference_moves_with_the_clip() -> None:
    limit = (0.002, math.radians(1.0))
    residual = np.array([1e-3, -2e-3, 0.01])  # 1 mm/s, -2 mm/s, 0.57 deg/s
    bounded = Episode(_scenario(), GAINS, offset_limit=limit)
    free = Episode(_scenario(), GAINS)
    for episode in (bounded, free):
        episode.reset()
    for n in range(1, 151):  # 1.5 s: y reaches its bound at 1 s, yaw at 1.75 s, x never
        bounded.step(residual)
        free.step(residual)
        expected = np.clip(n * 0.01 * residual, [-0.002] * 3, [0.002, 0.002, limit[1]])
        np.testing.assert_allclose(bounded.reference_offset, expected, rtol=1e-12, atol=1e-15)
    assert bounded.reference_offset[1] == -0.002
    assert free.reference_offset[1] == pytest.approx(-0.003, rel=1e-12)
    # until y clipped, the two pushes were the same to the bit; after, the bounded pusher
    # stops moving sideways: the object ends short of the free push's
    # y by up to the clipped millimetre
    a, b = bounded.trace().to_frame(), free.trace().to_frame()
    before = slice(0, 100)
    np.testing.assert_array_equal(a.to_numpy()[before], b.to_numpy()[before])
    shift = a["obj_y"].to_numpy()[-1] - b["obj_y"].to_numpy()[-1]
    assert 5e-5 < shift < 0.0012


@pytest.mark.parametrize("limit", [(0.0, 0.1), (0.01, -1.0), (math.nan, 0.1)])
def test_a_bad_offset_limit_is_one_line(limit) -> None:
    with pytest.raises(ConfigError, match="offset limit must be > 0"):
        Episode(_scenario(), GAINS, offset_limit=limit)


def test_an_infinite_offset_limit_is_no_limit_to_the_bit() -> None:
    residual = np.array([1e-3, -2e-3, 0.01])
    frames = []
    for limit in (None, (math.inf, math.inf)):
        episode = Episode(_scenario(), GAINS, offset_limit=limit)
        episode.reset()
        while not episode.done:
            episode.step(residual)
        frames.append(episode.trace().to_frame().to_numpy())
    assert frames[0].tobytes() == frames[1].tobytes()


def test_a_bad_residual_path_is_one_line() -> None:
    with pytest.raises(ConfigError, match="residual_path must be one of reference, velocity"):
        Episode(_scenario(), GAINS, residual_path="position")


@pytest.mark.parametrize("effects", [None, ProxyEffects()], ids=["sim", "proxy"])
def test_the_measured_pose_is_the_traces_camera_pose_step_by_step(effects) -> None:
    episode = Episode(_scenario(), GAINS, effects=effects)
    episode.reset()
    seen = [episode.measured_pose()]
    while not episode.done:
        episode.step()
        seen.append(episode.measured_pose())
    trace = episode.trace()
    expected = trace.object_pose if effects is None else trace.measured_pose
    np.testing.assert_allclose(np.array(seen), expected, rtol=0, atol=1e-12)
    if effects is not None:  # the camera's noise is there to read
        assert np.abs(np.array(seen) - trace.object_pose)[:, :2].max() > 1e-4
