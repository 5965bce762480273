"""The protocol: displacements in the object's initial frame, normalised mean squared error
per (surface, shape, speed) group, and mean position and angle errors.

NMSE of a component in a group = mean over the group's scored pushes of
(predicted − recorded displacement)², divided by the recorded displacement's variance over
those pushes (population variance). The overall NMSE is the mean over the three components
and over the groups.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from pushctl.realdata.data import GROUP

COMPONENTS = ("x", "y", "theta")


def wrap_angle(angle):
    """Angles [rad] wrapped to [−π, π)."""
    return (np.asarray(angle) + np.pi) % (2 * np.pi) - np.pi


def displacement(x0, y0, theta0, x1, y1, theta1) -> np.ndarray:
    """(N, 3): (dx, dy) [m] in the initial frame and dθ [rad], from start and end poses."""
    c, s = np.cos(theta0), np.sin(theta0)
    dx, dy = np.asarray(x1) - x0, np.asarray(y1) - y0
    return np.stack((c * dx + s * dy, -s * dx + c * dy, wrap_angle(np.asarray(theta1) - theta0)), 1)


def recorded(pushes: pd.DataFrame) -> np.ndarray:
    """Recorded displacements (N, 3)."""
    p = pushes
    return displacement(p.x0, p.y0, p.theta0, p.x1, p.y1, p.theta1)


def predicted(pushes: pd.DataFrame, end: np.ndarray) -> np.ndarray:
    """Displacements (N, 3) of predicted end poses ``end`` (N, 3) from the recorded starts."""
    p = pushes
    return displacement(p.x0, p.y0, p.theta0, end[:, 0], end[:, 1], end[:, 2])


def group_scores(pushes: pd.DataFrame, end: np.ndarray) -> pd.DataFrame:
    """Per group: n, NMSE of x, y, θ and their mean, mean position error [mm] and mean
    angle error [deg] of the predicted end poses ``end`` (N, 3) [m, m, rad]."""
    truth, guess = recorded(pushes), predicted(pushes, end)
    pos_err = np.hypot(end[:, 0] - pushes.x1.to_numpy(), end[:, 1] - pushes.y1.to_numpy())
    ang_err = np.abs(wrap_angle(end[:, 2] - pushes.theta1.to_numpy()))
    rows = []
    for key, index in sorted(pushes.groupby(list(GROUP)).groups.items()):
        i = pushes.index.get_indexer(index)
        variance = np.maximum(truth[i].var(axis=0), 1e-300)
        nmse = ((guess[i] - truth[i]) ** 2).mean(axis=0) / variance
        rows.append({
            **dict(zip(GROUP, key, strict=True)),
            "n": len(i),
            **{f"nmse_{c}": nmse[k] for k, c in enumerate(COMPONENTS)},
            "nmse": nmse.mean(),
            "position_error_mm": 1e3 * pos_err[i].mean(),
            "angle_error_deg": np.degrees(ang_err[i].mean()),
        })  # fmt: skip
    return pd.DataFrame(rows)


def overall(scores: pd.DataFrame) -> dict[str, float]:
    """Means over groups of a :func:`group_scores` table (errors weighted by pushes)."""
    w = scores["n"] / scores["n"].sum()
    return {
        **{f"nmse_{c}": float(scores[f"nmse_{c}"].mean()) for c in COMPONENTS},
        "nmse": float(scores["nmse"].mean()),
        "position_error_mm": float((scores["position_error_mm"] * w).sum()),
        "angle_error_deg": float((scores["angle_error_deg"] * w).sum()),
    }


def zhou_end(pushes: pd.DataFrame) -> np.ndarray | None:
    """Zhou's predicted end poses (N, 3), or None if the file has none."""
    columns = ["zhou_poly4_x1", "zhou_poly4_y1", "zhou_poly4_theta1"]
    if not all(c in pushes.columns for c in columns):
        return None
    return pushes[columns].to_numpy(dtype=float)
