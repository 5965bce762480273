"""One push, three ways: the world's own step (:meth:`World.push` on a world without an
arm), :mod:`pushctl.kinematic` (its front end) and an independent numpy step
(``reference_step``): the same trajectory to round-off, for a recorded push when the
recordings are present and for a made-up one always."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from reference_step import ReferencePushWorld

from pushctl.contact.world import World
from pushctl.kinematic import Friction, PressurePrior, Pusher, Slider, push_along
from pushctl.realdata.data import TIP_RADIUS, plate_mass

REAL_DATA = Path(
    os.environ.get(
        "PUSHCTL_REALDATA", Path(__file__).resolve().parents[2] / ".." / "shared" / "realdata"
    )
)
TRIANGLE = np.array([(0.045, -0.08), (0.045, 0.045), (-0.08, 0.045)])
STEP = 2e-3
"""Tip travel per step [m], as the replay's."""


def _recorded_push() -> tuple[np.ndarray, dict]:
    """tri3's first push on abs (its footprint and row) from the recordings."""
    if not (REAL_DATA / "mit" / "pushes.csv").is_file():
        pytest.skip(f"the recorded pushes are not at {REAL_DATA}")
    pushes = pd.read_csv(REAL_DATA / "mit" / "pushes.csv", comment="#")
    shapes = pd.read_csv(REAL_DATA / "mit" / "shapes.csv", comment="#")
    row = pushes[(pushes["shape"] == "tri3") & (pushes["surface"] == "abs")].iloc[0]
    vertices = shapes[shapes["shape"] == "tri3"].sort_values("vertex")[["x", "y"]].to_numpy()
    return vertices, row.to_dict()


def _made_up_push() -> tuple[np.ndarray, dict]:
    """A push of the off-centroid-framed triangle 50 mm along −x, 20 mm off its centroid."""
    return TRIANGLE, {"x0": 0.01, "y0": -0.02, "theta0": 0.3, "speed_mm_s": 20.0,
                      **_tip_line(0.01, -0.02, 0.3)}  # fmt: skip


def _tip_line(x0, y0, th0):
    c, s = math.cos(th0), math.sin(th0)
    start, end = np.array((0.045 + TIP_RADIUS + 2e-4, -0.02)), np.array((-0.005, -0.03))
    tx0, ty0 = x0 + c * start[0] - s * start[1], y0 + s * start[0] + c * start[1]
    tx1, ty1 = x0 + c * end[0] - s * end[1], y0 + s * end[0] + c * end[1]
    return {"tip_x0": tx0, "tip_y0": ty0, "tip_x1": tx1, "tip_y1": ty1}


def _path(row: dict) -> tuple[np.ndarray, float]:
    """The tip's poses (T, 3) along its line, STEP apart, and the step [s]."""
    start = np.array((row["tip_x0"], row["tip_y0"]))
    end = np.array((row["tip_x1"], row["tip_y1"]))
    length = float(np.hypot(*(end - start)))
    steps = max(1, math.ceil(length / STEP - 1e-9))
    s = np.minimum(np.arange(steps + 1) * STEP / length, 1.0)
    heading = math.atan2(*(end - start)[::-1])
    path = np.column_stack((start + s[:, None] * (end - start), np.full(len(s), heading)))
    return path, STEP / (row["speed_mm_s"] * 1e-3)


def _three_ways(vertices, row, friction):
    slider = Slider.from_vertices(vertices, plate_mass(vertices), PressurePrior(16, 3.0))
    path, dt = _path(row)
    pose = (row["x0"], row["y0"], row["theta0"])
    pusher = Pusher(((0.0, 0.0),), TIP_RADIUS)
    front_end = push_along(slider, path, object_pose=pose, dt=dt, pusher=pusher,
                           friction=friction).poses  # fmt: skip
    world = World(slider, None, friction.world_config(dt))  # type: ignore[arg-type]
    world.reset(slider.centroid_pose(np.array(pose)))
    own = [slider.frame_pose(world.object_pose)]
    for a, b in zip(path[:-1], path[1:], strict=True):
        world.push(a[None, :2], (b[None, :2] - a[None, :2]) / dt, TIP_RADIUS)
        own.append(slider.frame_pose(world.object_pose))
    reference = ReferencePushWorld(slider, pusher, friction, dt)
    reference.reset(pose)
    independent = [reference.pose]
    for a, b in zip(path[:-1], path[1:], strict=True):
        reference.step(a, b)
        independent.append(reference.pose)
    return front_end, np.array(own), np.array(independent)


@pytest.mark.parametrize("push", [_made_up_push, _recorded_push], ids=["made_up", "recorded"])
@pytest.mark.parametrize("friction", [Friction(0.25, 0.6, "polygon", 8),
                                      Friction(0.25, 0.6, "polygon", 16),
                                      Friction(0.25, 0.6, "axis_box")],
                         ids=["8-gon", "16-gon", "axis_box"])  # fmt: skip
def test_world_step_kinematic_and_reference_give_one_trajectory(push, friction):
    vertices, row = push()
    front_end, own, independent = _three_ways(vertices, row, friction)
    assert np.array_equal(front_end, own)  # the front end is the world's step
    deviation = np.abs(own - independent).max(axis=0)
    assert deviation[:2].max() < 1e-12 and deviation[2] < 1e-11, deviation
    assert abs(own[-1, 2] - own[0, 2]) > 0.01 or np.hypot(*(own[-1, :2] - own[0, :2])) > 0.01
