"""The two-finger pushing logs: each push segment replayed from its logged start with the
logged pusher motion, scored against the spread of the repeats of the same start.

A log (``two_finger_logs/<setup>/<start>/log*.txt``, no header) has columns t [s], object
x, y [mm], θ [rad], pusher x, y [mm], θ [rad], action id. Its first row is dropped, and
so are object poses of exactly (0, 0, 0) (vision dropouts). A segment is a run of rows
with one action id and no gap over 0.5 s (the pusher is lifted and moved between
segments). The pusher is two round fingers 18 mm apart across the push direction θ.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from itertools import combinations
from pathlib import Path

import numpy as np
import pandas as pd

from pushctl.errors import ConfigError
from pushctl.kinematic import Friction, KinematicPushWorld, PressurePrior, Pusher, Slider
from pushctl.realdata.metrics import wrap_angle

FINGER_RADIUS = 2.5e-3
FINGER_SPACING = 18e-3
RECTANGLE = (0.050, 0.035)
"""The logs' object: a 50 × 35 mm rectangle, its pose frame at the centre, 50 mm along x."""
RECTANGLE_MASS = 0.2
"""[kg] assumed (not recorded); the pushes are slow enough for it not to matter."""
LOG_MU_CONTACT = 0.3
"""The planner's finger–object μ for these runs, used as is (the logs are not fitted)."""
SEGMENT_GAP = 0.5
STEP = 0.05
"""Replay step [s]: about 1 mm of pusher motion at the logs' speeds."""


@dataclass(frozen=True)
class Segment:
    """One push segment of a ``setup`` (the support under the object) and ``start``: ``t``
    (n,) [s], ``object`` (n, 3) and ``pusher`` (n, 3) poses [m, m, rad]; ``fresh`` (n,)
    rows whose object pose changed (not a stale frame)."""

    setup: str
    start: str
    log: str
    index: int
    t: np.ndarray
    object: np.ndarray
    pusher: np.ndarray
    fresh: np.ndarray


def read_segments(data_dir: Path) -> list[Segment]:
    """Every segment of every log under ``DATA/two_finger_logs``."""
    root = Path(data_dir) / "two_finger_logs"
    files = sorted(root.glob("*/*/log*.txt"))
    if not files:
        raise ConfigError(f"{root}: no logs (two_finger_logs/<setup>/<start>/log*.txt)")
    segments = []
    for path in files:
        segments += _segments_of(path, path.parent.parent.name, path.parent.name)
    return segments


def _segments_of(path: Path, setup: str, start: str) -> list[Segment]:
    try:
        table = np.loadtxt(path, delimiter=",", ndmin=2)
    except ValueError:
        raise ConfigError(f"{path}: not a log of 8 numeric columns") from None
    if table.shape[1] != 8 or len(table) < 3:
        raise ConfigError(f"{path}: expected 8 columns and rows, got shape {table.shape}")
    table = table[1:]
    # Segments from the pusher's rows, which are never dropped; then the dropouts go.
    cut = (np.diff(table[:, 0]) > SEGMENT_GAP) | (np.diff(table[:, 7]) != 0)
    pieces = np.split(table, np.flatnonzero(cut) + 1)
    out: list[Segment] = []
    for piece in pieces:
        piece = piece[np.any(piece[:, 1:4] != 0, axis=1)]
        if len(piece) < 10:
            continue
        obj = np.column_stack((piece[:, 1:3] * 1e-3, np.unwrap(piece[:, 3])))
        push = np.column_stack((piece[:, 4:6] * 1e-3, np.unwrap(piece[:, 6])))
        fresh = np.r_[True, np.any(np.diff(piece[:, 1:4], axis=0) != 0, axis=1)]
        out.append(Segment(setup, start, path.name, len(out), piece[:, 0], obj, push, fresh))
    return out


def replay_segment(segment: Segment, friction: Friction, prior: PressurePrior) -> np.ndarray:
    """Replayed object poses (n, 3) at the segment's row times, from its first pose."""
    w, h = RECTANGLE
    rect = [(-w / 2, -h / 2), (w / 2, -h / 2), (w / 2, h / 2), (-w / 2, h / 2)]
    slider = Slider.from_vertices(rect, RECTANGLE_MASS, prior)
    pusher = Pusher.row(2, FINGER_SPACING, FINGER_RADIUS)
    t = segment.t - segment.t[0]
    grid = np.arange(0.0, t[-1] + STEP, STEP)
    path = np.column_stack([np.interp(grid, t, segment.pusher[:, k]) for k in range(3)])
    world = KinematicPushWorld(slider, pusher, friction, STEP)
    world.reset(segment.object[0])
    poses = np.empty((len(grid), 3))
    poses[0] = world.pose
    for k in range(len(grid) - 1):
        world.step(path[k], path[k + 1])
        poses[k + 1] = world.pose
    return np.column_stack([np.interp(t, grid, poses[:, k]) for k in range(3)])


def score_segments(segments: list[Segment], replays: list[np.ndarray]) -> pd.DataFrame:
    """Per segment: path RMSE [mm] over its fresh rows, end position [mm] and angle [deg]
    errors, and the repeat floor of its start and segment index: the median over pairs of
    repeats of their end poses' distance [mm] and angle difference [deg]."""
    floors = repeat_floors(segments)
    rows = []
    for seg, replay in zip(segments, replays, strict=True):
        f = seg.fresh
        err = np.hypot(*(replay[f, :2] - seg.object[f, :2]).T)
        end_pos, end_ang = end_error(seg, replay)
        moved = 1e3 * math.hypot(*(seg.object[-1, :2] - seg.object[0, :2]))
        floor_pos, floor_ang, repeats = floors[(seg.start, seg.index)]
        rows.append({
            "setup": seg.setup, "start": seg.start, "log": seg.log, "segment": seg.index,
            "repeats": repeats,
            "moved_mm": moved, "path_rmse_mm": 1e3 * math.sqrt(float((err**2).mean())),
            "end_position_error_mm": end_pos, "end_angle_error_deg": end_ang,
            "floor_position_mm": floor_pos, "floor_angle_deg": floor_ang,
            "within_3x_floor": bool(end_pos <= 3 * floor_pos and end_ang <= 3 * floor_ang),
        })  # fmt: skip
    return pd.DataFrame(rows)


def end_error(segment: Segment, replay: np.ndarray) -> tuple[float, float]:
    """The replay's end position [mm] and angle [deg] error against the segment's end."""
    end_pos = 1e3 * math.hypot(*(replay[-1, :2] - segment.object[-1, :2]))
    end_ang = math.degrees(abs(float(wrap_angle(replay[-1, 2] - segment.object[-1, 2]))))
    return end_pos, end_ang


def repeat_floors(segments: list[Segment]) -> dict[tuple[str, int], tuple[float, float, int]]:
    """(start, segment index) → the repeats' floor: median pairwise end distance [mm] and
    angle difference [deg], and the number of repeats."""
    ends: dict[tuple[str, int], list[np.ndarray]] = {}
    for seg in segments:
        ends.setdefault((seg.start, seg.index), []).append(seg.object[-1])
    return {key: _floor(np.array(v)) for key, v in ends.items()}


def _floor(end_poses: np.ndarray) -> tuple[float, float, int]:
    """Median pairwise end-position distance [mm] and angle difference [deg] of repeats."""
    if len(end_poses) < 2:
        return math.nan, math.nan, len(end_poses)
    pairs = list(combinations(range(len(end_poses)), 2))
    pos = [1e3 * math.hypot(*(end_poses[i, :2] - end_poses[j, :2])) for i, j in pairs]
    ang = [math.degrees(abs(float(wrap_angle(end_poses[i, 2] - end_poses[j, 2]))))
           for i, j in pairs]  # fmt: skip
    return float(np.median(pos)), float(np.median(ang)), len(end_poses)
