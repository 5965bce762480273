"""The two protocols end to end, as plain functions returning data (the CLI writes it):
fitting on the calibration split, scoring every push beside Zhou's predictions, and
replaying the two-finger logs.

The fit file records the split (seed, excluded shapes, and a digest of the calibration
push ids); scoring on the same data scores the test split (``split = test``), on other
data every push is unseen by the fit and is scored as such. Every table also has an
``all`` split.
"""

from __future__ import annotations

import hashlib
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from pushctl.errors import ConfigError
from pushctl.kinematic import Friction, PressurePrior
from pushctl.realdata.data import PushData, calibration_mask, load_pushes
from pushctl.realdata.fit import FitGrids, fit_surfaces, friction_toml
from pushctl.realdata.logfit import LogGrids, fit_logs
from pushctl.realdata.logs import LOG_MU_CONTACT, read_segments, replay_segment, score_segments
from pushctl.realdata.metrics import COMPONENTS, group_scores, overall, zhou_end
from pushctl.realdata.replay import DEFAULT_FACETS, ReplaySettings, SurfaceParameters, replay_pushes


def calibration_split(data: PushData, seed: int, exclude: Sequence[str]) -> np.ndarray:
    """The calibration mask (N,) of a fit: the seeded 20 % minus the excluded shapes."""
    unknown = sorted(set(exclude) - set(data.pushes["shape"]))
    if unknown:
        raise ConfigError(f"--exclude-shape: no pushes of {', '.join(unknown)} in the data")
    return calibration_mask(data.pushes, seed) & ~data.pushes["shape"].isin(exclude).to_numpy()


def split_digest(pushes: pd.DataFrame, mask: np.ndarray) -> str:
    """A digest of the calibration push ids (order-independent)."""
    ids = "\n".join(sorted(pushes.loc[mask, "push_id"].astype(str)))
    return hashlib.sha256(ids.encode()).hexdigest()[:16]


def run_fit(
    data_dir: Path,
    seed: int,
    exclude: Sequence[str],
    settings: ReplaySettings,
    header: list[str],
    workers: int = 1,
    progress: Callable[[str], None] | None = None,
    grids: FitGrids | None = None,
) -> str:
    """Fit every surface on the calibration split; the TOML text to write."""
    data = load_pushes(data_dir)
    mask = calibration_split(data, seed, exclude)
    calibration = data.pushes[mask].reset_index(drop=True)
    grids = grids if grids is not None else FitGrids()
    fits = fit_surfaces(calibration, data.shapes, settings, workers, progress, grids)
    header = header + [
        f"split: seed {seed}, 20 % of each surface x shape x speed group, "
        f"{int(mask.sum())} calibration pushes, excluded shapes: {', '.join(exclude) or 'none'}",
    ]
    text = friction_toml(fits, settings, header)
    return text + (
        f"\n[split]\nseed = {seed}\nexclude_shapes = {list(exclude)!r}\n"
        f'calibration_digest = "{split_digest(data.pushes, mask)}"\n'
        f"pushes = {len(data.pushes)}\n"
    ).replace("'", '"')


@dataclass(frozen=True)
class ScoreResult:
    """``predictions`` (push_id, x1, y1, theta1), ``summary`` (per group and split, ours
    and Zhou's), the pushes scored, our and Zhou's end poses (N, 3), the seconds the
    replay took and whether the fit's calibration split was recognised."""

    predictions: pd.DataFrame
    summary: pd.DataFrame
    pushes: pd.DataFrame
    shapes: dict
    ours: np.ndarray
    zhou: np.ndarray | None
    seconds: float
    split_known: bool


def run_score(
    data_dir: Path,
    params: dict[str, SurfaceParameters],
    settings: ReplaySettings,
    split: dict,
    only_shapes: Sequence[str] = (),
    workers: int = 1,
) -> ScoreResult:
    """Replay every push (or those of ``only_shapes``) and score them."""
    data = load_pushes(data_dir)
    mask = np.zeros(len(data.pushes), dtype=bool)
    known = False
    if "seed" in split:
        mask = calibration_split(data, int(split["seed"]), split.get("exclude_shapes", []))
        known = split_digest(data.pushes, mask) == split.get("calibration_digest")
        fitted_on = int(split.get("pushes", 0))
        if len(data.pushes) < fitted_on:
            raise ConfigError(
                f"{data_dir / 'mit' / 'pushes.csv'} holds {len(data.pushes)} pushes, fewer than "
                f"the {fitted_on} the fit was made on: cut short? Score the data the fit was "
                "made on (--shapes picks some of it)"
            )
        if not known:
            mask[:] = False  # another data set: every push is unseen by the fit
    pushes = data.pushes.assign(_calibration=mask)
    if only_shapes:
        unknown = sorted(set(only_shapes) - set(pushes["shape"]))
        if unknown:
            raise ConfigError(f"--shapes: no pushes of {', '.join(unknown)} in the data")
        pushes = pushes[pushes["shape"].isin(only_shapes)]
    pushes = pushes.reset_index(drop=True)
    start = time.perf_counter()
    ours = replay_pushes(pushes, data.shapes, params, settings, workers)
    seconds = time.perf_counter() - start
    zhou = zhou_end(pushes)
    predictions = pd.DataFrame(
        {"push_id": pushes["push_id"], "x1": ours[:, 0], "y1": ours[:, 1], "theta1": ours[:, 2]}
    )
    parts = []
    test = ~pushes["_calibration"].to_numpy()
    for name, rows in (("test", test), ("all", np.ones(len(pushes), dtype=bool))):
        parts.append(_summary(pushes[rows].reset_index(drop=True), ours[rows],
                              None if zhou is None else zhou[rows], name))  # fmt: skip
    summary = pd.concat(parts, ignore_index=True)
    return ScoreResult(predictions, summary, pushes.drop(columns="_calibration"), data.shapes,
                       ours, zhou, seconds, known)  # fmt: skip


_METRICS = [*(f"nmse_{c}" for c in COMPONENTS), "nmse", "position_error_mm", "angle_error_deg"]


def _summary(pushes: pd.DataFrame, ours: np.ndarray, zhou, split: str) -> pd.DataFrame:
    """Per-group rows and one overall row (surface ``all``) of one split."""
    if len(pushes) == 0:
        return pd.DataFrame()
    mine = group_scores(pushes, ours)
    table = mine.copy()
    totals = {"surface": "all", "shape": "all", "speed_mm_s": 0, "n": int(mine["n"].sum()),
              **overall(mine)}  # fmt: skip
    if zhou is not None:
        theirs = group_scores(pushes, zhou)
        for m in _METRICS:
            table[f"zhou_{m}"] = theirs[m].to_numpy()
            totals[f"zhou_{m}"] = overall(theirs)[m]
    table = pd.concat([table, pd.DataFrame([totals])], ignore_index=True)
    table.insert(0, "split", split)
    return table


def run_logs(
    data_dir: Path,
    prior: PressurePrior,
    model: str,
    mu_ground: float = 0.3,
    fit: bool = False,
    progress: Callable[[str], None] | None = None,
    facets: int = DEFAULT_FACETS,
):
    """Replay every two-finger segment with ground friction ``model`` (``facets`` sides for
    the polygon); (per-segment scores, segments, replays). With
    ``fit``, each start is replayed with μ_c and the rim weight fitted on its setup's other
    starts (:func:`~pushctl.realdata.logfit.fit_logs`); else with ``prior`` and the
    planner's μ_c."""
    segments = read_segments(data_dir)
    if fit:
        grids = LogGrids(mu_ground=mu_ground, support_count=prior.count, facets=facets)
        fitted = fit_logs(segments, model, grids, progress)
        return fitted.table, segments, fitted.replays
    friction = Friction(LOG_MU_CONTACT, mu_ground, model, facets)
    replays = [replay_segment(s, friction, prior) for s in segments]
    return score_segments(segments, replays), segments, replays
