"""Leave one shape out: for each shape in the data, fit every surface on the other shapes'
calibration pushes and score all pushes of the held-out shape (none was seen by its fit).

The folds share one :class:`~pushctl.realdata.fit.ReplayCache`: a calibration push is
replayed once per parameter set, however many folds try that set. The result does not
depend on the number of workers.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from pushctl.errors import ConfigError
from pushctl.realdata.data import calibration_mask, load_pushes
from pushctl.realdata.fit import FitGrids, ReplayCache, fit_surfaces
from pushctl.realdata.metrics import group_scores, overall, zhou_end
from pushctl.realdata.replay import ReplaySettings, SurfaceParameters

PARAMETERS = ("mu_contact", "mu_ground", "rim_weight")


@dataclass(frozen=True)
class LosoResult:
    """``table``: one row per held-out shape and a last row (``shape`` ``all``) over every
    held-out push; ``predictions``: (push_id, x1, y1, theta1) of every push, each predicted
    by the fit that did not see its shape; ``groups``: per (surface, shape, speed) scores
    of those predictions (ours and Zhou's)."""

    table: pd.DataFrame
    predictions: pd.DataFrame
    groups: pd.DataFrame


def run_loso(
    data_dir: Path,
    seed: int,
    settings: ReplaySettings,
    grids: FitGrids | None = None,
    workers: int = 1,
    progress: Callable[[str], None] | None = None,
) -> LosoResult:
    """All leave-one-shape-out folds of the data in ``data_dir`` (split ``seed``)."""
    grids = grids if grids is not None else FitGrids()
    data = load_pushes(data_dir)
    pushes = data.pushes
    names = sorted(pushes["shape"].unique())
    if len(names) < 2:
        raise ConfigError(f"leave-one-shape-out needs two shapes or more, the data has {names}")
    calibration = calibration_mask(pushes, seed)
    cache = ReplayCache(data.shapes, settings, workers)
    ends = np.full((len(pushes), 3), np.nan)
    rows = []
    for name in names:
        held = (pushes["shape"] == name).to_numpy()
        train = pushes[calibration & ~held].reset_index(drop=True)
        unfitted = sorted(set(pushes.loc[held, "surface"]) - set(train["surface"]))
        if unfitted:
            raise ConfigError(f"no other shape on surface(s) {unfitted} to fit {name!r} from")
        fits = fit_surfaces(train, data.shapes, settings, workers,
                            _prefixed(progress, f"without {name}: "), grids, cache)  # fmt: skip
        for surface in sorted(pushes.loc[held, "surface"].unique()):
            index = np.flatnonzero(held & (pushes["surface"] == surface).to_numpy())
            part = pushes.iloc[index].reset_index(drop=True)
            ends[index] = cache.ends(part, surface, fits[surface]["parameters"])
        row = {"shape": name, **_fitted(fits), **_scores(pushes[held], ends[held])}
        rows.append(row)
        if progress is not None:
            progress(f"held out {name}: n {row['n']}, NMSE {row['nmse']:.3f}")
    rows.append({"shape": "all", **_scores(pushes, ends)})
    table = pd.DataFrame(rows)
    predictions = pd.DataFrame({"push_id": pushes["push_id"], "x1": ends[:, 0],
                                "y1": ends[:, 1], "theta1": ends[:, 2]})  # fmt: skip
    return LosoResult(table, predictions, _groups(pushes, ends))


def _prefixed(progress: Callable[[str], None] | None, prefix: str):
    if progress is None:
        return None
    return lambda line: progress(prefix + line)


def _fitted(fits: dict[str, dict]) -> dict[str, float]:
    """``<surface>_<parameter>`` and ``<surface>_calibration_nmse`` of one fold's fits."""
    out: dict[str, float] = {}
    for surface, fit in sorted(fits.items()):
        params: SurfaceParameters = fit["parameters"]
        out.update({f"{surface}_{p}": float(getattr(params, p)) for p in PARAMETERS})
        out[f"{surface}_calibration_nmse"] = float(fit["calibration_nmse"])
    return out


def _scores(pushes: pd.DataFrame, ends: np.ndarray) -> dict[str, float]:
    """n, our NMSE (x, y, θ, mean), position [mm] and angle [deg] error over ``pushes``'
    groups, and Zhou's on the same pushes when the data has his columns."""
    pushes = pushes.reset_index(drop=True)
    out: dict[str, float] = {"n": len(pushes), **overall(group_scores(pushes, ends))}
    zhou = zhou_end(pushes)
    if zhou is not None:
        out.update({f"zhou_{k}": v for k, v in overall(group_scores(pushes, zhou)).items()})
    return out


def _groups(pushes: pd.DataFrame, ends: np.ndarray) -> pd.DataFrame:
    table = group_scores(pushes, ends)
    zhou = zhou_end(pushes)
    if zhou is not None:
        theirs = group_scores(pushes, zhou)
        for column in theirs.columns[len(("surface", "shape", "speed_mm_s", "n")) :]:
            table[f"zhou_{column}"] = theirs[column].to_numpy()
    return table
