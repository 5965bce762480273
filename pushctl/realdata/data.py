"""Reading recorded pushes: the MIT push dataset's single pushes and their footprints, in the
CSV layout described in docs/realdata.md, and the seeded calibration/test split.

Pushes are rows of ``mit/pushes.csv`` (metres, radians, mm/s), footprints rows of
``mit/shapes.csv`` (vertices in each object's pose frame [m], counter-clockwise). Every
problem with the files is a :class:`~pushctl.errors.ConfigError` naming the file and what
is wrong.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from pushctl.errors import ConfigError

PUSH_COLUMNS = (
    "push_id", "surface", "shape", "speed_mm_s",
    "x0", "y0", "theta0", "x1", "y1", "theta1",
    "tip_x0", "tip_y0", "tip_x1", "tip_y1",
)  # fmt: skip
"""Columns every pushes file must have; ``zhou_poly4_{x1,y1,theta1}`` are optional."""

GROUP = ("surface", "shape", "speed_mm_s")
"""A push's group: the protocol normalises and averages per group."""

CALIBRATION_SHARE = 0.2

TIP_RADIUS = 4.75e-3
"""The MIT dataset's round steel tip [m]."""

PLATE_THICKNESS = 0.013
STEEL_DENSITY = 7900.0
"""The plates' masses are not in the records: they are taken as 13 mm stainless steel
[m, kg/m³]. The pushes are quasi-static, so the predictions barely depend on it."""


@dataclass(frozen=True)
class PushData:
    """Pushes (one row each, columns :data:`PUSH_COLUMNS` and maybe Zhou's) and footprints
    (shape name → vertices (V, 2) [m] in the pose frame)."""

    pushes: pd.DataFrame
    shapes: dict[str, np.ndarray]


def load_pushes(data_dir: Path) -> PushData:
    """Read ``DATA/mit/pushes.csv`` and ``DATA/mit/shapes.csv`` and check them."""
    data_dir = Path(data_dir)
    if not data_dir.is_dir():
        raise ConfigError(f"--data: {data_dir} is not a directory")
    pushes = _read_csv(data_dir / "mit" / "pushes.csv")
    shapes_table = _read_csv(data_dir / "mit" / "shapes.csv")
    missing = [c for c in PUSH_COLUMNS if c not in pushes.columns]
    if missing:
        raise ConfigError(
            f"{data_dir / 'mit' / 'pushes.csv'}: missing columns {', '.join(missing)}"
        )
    for column in ("shape", "vertex", "x", "y"):
        if column not in shapes_table.columns:
            raise ConfigError(f"{data_dir / 'mit' / 'shapes.csv'}: missing column {column!r}")
    numeric = [c for c in PUSH_COLUMNS if c not in ("push_id", "surface", "shape")]
    values = pushes[numeric].apply(pd.to_numeric, errors="coerce")
    if not np.isfinite(values.to_numpy(dtype=float)).all():
        raise ConfigError(f"{data_dir / 'mit' / 'pushes.csv'}: non-numeric or missing values")
    if (values["speed_mm_s"] <= 0).any():
        raise ConfigError(f"{data_dir / 'mit' / 'pushes.csv'}: speed_mm_s must be positive")
    if pushes["push_id"].duplicated().any():
        raise ConfigError(f"{data_dir / 'mit' / 'pushes.csv'}: push_id is not unique")
    shapes = {
        str(name): group.sort_values("vertex")[["x", "y"]].to_numpy(dtype=float)
        for name, group in shapes_table.groupby("shape")
    }
    unknown = sorted(set(pushes["shape"].astype(str)) - set(shapes))
    if unknown:
        raise ConfigError(f"pushes name shapes not in shapes.csv: {', '.join(unknown)}")
    pushes = pushes.astype({"shape": str, "surface": str, "push_id": str})
    return PushData(pushes.reset_index(drop=True), shapes)


def _read_csv(path: Path) -> pd.DataFrame:
    if not path.is_file():
        raise ConfigError(f"{path} does not exist")
    try:
        frame = pd.read_csv(path, comment="#")
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as error:
        raise ConfigError(f"{path}: not a readable CSV ({error.__class__.__name__})") from None
    if frame.empty:
        raise ConfigError(f"{path} holds no rows")
    return frame


def calibration_mask(pushes: pd.DataFrame, seed: int, share: float = CALIBRATION_SHARE):
    """Boolean (N,): ``share`` of each (surface, shape, speed) group, drawn with ``seed``
    (at least one push per group of two or more); the rest is the test split. The draw
    depends only on the seed and each group's push ids, not on the file's row order."""
    mask = np.zeros(len(pushes), dtype=bool)
    for key, index in sorted(pushes.groupby(list(GROUP)).groups.items()):
        ids = pushes.loc[index, "push_id"].to_numpy(dtype=str)
        order = np.argsort(ids, kind="stable")
        rng = np.random.default_rng([seed, _stable_hash(key)])
        take = math.ceil(share * len(ids)) if len(ids) > 1 else 0
        chosen = rng.permutation(len(ids))[:take]
        mask[np.asarray(index)[order[chosen]]] = True
    return mask


def _stable_hash(key: tuple) -> int:
    """A process-independent integer of a group key (Python's hash() is salted)."""
    text = "|".join(str(k) for k in key)
    return int.from_bytes(text.encode(), "little") % (2**63)


def plate_mass(vertices: np.ndarray) -> float:
    """[kg] of a :data:`PLATE_THICKNESS` steel plate with this footprint (V, 2) [m]."""
    x, y = vertices[:, 0], vertices[:, 1]
    area = 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))
    return area * PLATE_THICKNESS * STEEL_DENSITY
