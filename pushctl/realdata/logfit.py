"""Fitting the two-finger logs' contact parameters per setup, leaving one start out.

The logs' support (``_3pts``: three points, ``_ridge``: a ridge) and finger friction are
not recorded. Per setup and per start, μ_c and the pressure prior's rim weight are chosen
over a fixed grid (:class:`LogGrids`) on the setup's *other* starts' segments, and the
start's own segments are replayed with that choice: no segment is scored with parameters
fitted on it. The loss is the mean over the fitted segments of
log(max(end position error / floor, end angle error / floor)): the quantity the
acceptance thresholds at log 3.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from pushctl.errors import ConfigError
from pushctl.kinematic import Friction, PressurePrior
from pushctl.realdata.logs import Segment, end_error, repeat_floors, replay_segment
from pushctl.realdata.logs import score_segments as _score
from pushctl.realdata.replay import DEFAULT_FACETS


@dataclass(frozen=True)
class LogGrids:
    """The grid searched per setup: finger–object μ_c [-] and the rim weight [-]; the
    replay's μ_g, support points and polygon facets."""

    mu_contact: tuple[float, ...] = (0.2, 0.3, 0.4, 0.5)
    rim_weight: tuple[float, ...] = (-2.0, 0.0, 2.0, 4.0)
    mu_ground: float = 0.3
    support_count: int = 16
    facets: int = DEFAULT_FACETS


@dataclass(frozen=True)
class LogFit:
    """``table``: :func:`~pushctl.realdata.logs.score_segments` with the parameters each
    segment was replayed with (``mu_contact``, ``rim_weight``: fitted without its start);
    ``replays``: the replayed poses, one (n, 3) per segment."""

    table: pd.DataFrame
    replays: list[np.ndarray] = field(repr=False)


def fit_logs(
    segments: list[Segment],
    model: str,
    grids: LogGrids = LogGrids(),
    progress: Callable[[str], None] | None = None,
) -> LogFit:
    """Leave-one-start-out fits of every setup in ``segments`` and their replays."""
    floors = repeat_floors(segments)
    cache: dict[tuple[float, float, int], np.ndarray] = {}

    def replay(i: int, mu: float, rim: float) -> np.ndarray:
        if (mu, rim, i) not in cache:
            friction = Friction(mu, grids.mu_ground, model, grids.facets)
            prior = PressurePrior(grids.support_count, rim)
            cache[(mu, rim, i)] = replay_segment(segments[i], friction, prior)
        return cache[(mu, rim, i)]

    def loss(indices: list[int], mu: float, rim: float) -> float:
        ratios = []
        for i in indices:
            pos, ang = end_error(segments[i], replay(i, mu, rim))
            floor_pos, floor_ang, _ = floors[(segments[i].start, segments[i].index)]
            if math.isfinite(floor_pos):
                ratios.append(max(pos / max(floor_pos, 1e-3), ang / max(floor_ang, 1e-3)))
        return float(np.mean(np.log(ratios))) if ratios else math.inf

    chosen: list[tuple[float, float]] = [(math.nan, math.nan)] * len(segments)
    grid = [(mu, rim) for mu in grids.mu_contact for rim in grids.rim_weight]
    for setup in sorted({s.setup for s in segments}):
        starts = sorted({s.start for s in segments if s.setup == setup})
        if len(starts) < 2:
            raise ConfigError(f"setup {setup!r} has one start: nothing to fit it on")
        for held in starts:
            train = [i for i, s in enumerate(segments) if s.setup == setup and s.start != held]
            losses = [loss(train, mu, rim) for mu, rim in grid]
            # ties (to round-off: a straight push does not see the rim weight) go to the
            # first grid point, whatever the last bits of the replays
            tied = np.asarray(losses) <= min(losses) + 1e-9 * abs(min(losses))
            best = grid[int(np.argmax(tied))]
            for i, s in enumerate(segments):
                if s.start == held:
                    chosen[i] = best
            if progress is not None:
                progress(f"{held}: fitted on {len(train)} other segments: mu_c {best[0]}, "
                         f"rim weight {best[1]}, loss {min(losses):.3f}")  # fmt: skip
    replays = [replay(i, mu, rim) for i, (mu, rim) in enumerate(chosen)]
    table = _score(segments, replays)
    table.insert(4, "mu_contact", [mu for mu, _ in chosen])
    table.insert(5, "rim_weight", [rim for _, rim in chosen])
    return LogFit(table, replays)
