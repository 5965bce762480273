"""``pushctl tune-pd``: the PD baseline's gains, chosen by a documented search.

The procedure (docs/design.md §5: never on the evaluation set):

1. Tuning set: for every object × profile, ``per_case`` scenarios drawn from the *tuning*
   random stream of ``seed`` (:func:`pushctl.episode.scenario.stream_rng`), goals from the
   evaluation's target ranges, the plant drawn from the ``sim`` ranges (the plant the
   baseline is evaluated on), goals the planner rejects redrawn.
2. Objective: the mean over the tuning set of the tracking error, translation error % +
   angle error % (docs/design.md §7). A candidate whose episode fails (non-finite state) scores
   infinity.
3. Search over (K_p, K_v, K_x) with K_x shared by the position and orientation feedback:
   a coarse grid (:data:`GRID`), then coordinate refinement from the best point — each gain
   multiplied and divided by a factor starting at 2 (K_p also tried at 0, or from 0 at
   :data:`KP_FROM_ZERO`), the best move kept when it lowers the objective, the factor
   square-rooted whenever a sweep gains nothing — until the factor falls below 1.1 or after
   ``max_rounds`` sweeps. Bounds (:data:`BOUNDS`): K_x ≤ 0.5/h keeps
   the discrete task loop well inside its stability limit (K_x h < 1); K_v ≤ 300 N·m·s/rad
   stays in the range the implicit damping was validated on; K_p ≤ 3000 N·m/rad.

The damped-pseudo-inverse λ and the posture gain are not searched: λ only acts near
singularities (cond J ≤ 15 in the workspace) and the posture task lives in the null space.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from pushctl.control.gains import PDGains
from pushctl.episode.draw import draw_scenario
from pushctl.episode.metrics import compute_metrics
from pushctl.episode.runner import Episode
from pushctl.episode.scenario import Scenario
from pushctl.errors import ConfigError, PushctlError

GRID = {
    "kp": (0.0, 300.0),
    "kv": (10.0, 30.0, 100.0, 300.0),
    "kx": (5.0, 15.0, 50.0),
}
"""The coarse grid (K_p [N·m/rad], K_v [N·m·s/rad], K_x [1/s]): 24 candidates."""

BOUNDS = {"kp": (0.0, 3000.0), "kv": (1.0, 300.0), "kx": (0.5, 50.0)}
"""Search bounds per gain (K_x's upper bound is 0.5/h at h = 0.01 s; see the module doc)."""


@dataclass(frozen=True)
class Candidate:
    """One evaluated gain set: its objective (mean translation % + angle %) and the
    mean of each part over the tuning set."""

    gains: PDGains
    objective: float
    translation_error_pct: float
    angle_error_pct: float


@dataclass(frozen=True)
class TuningResult:
    """The best candidate, every candidate in the order evaluated, and the tuning set."""

    best: Candidate
    candidates: tuple[Candidate, ...]
    scenarios: tuple[Scenario, ...]
    redrawn: int


def tuning_scenarios(
    seed: int,
    objects: tuple[str, ...],
    profiles: tuple[str, ...],
    per_case: int,
    duration: float = 20.0,
) -> tuple[list[Scenario], int]:
    """The tuning set and the number of goals redrawn while drawing it. Scenario i of an
    object × profile case uses seed ``seed + i`` on the tuning stream."""
    if not (isinstance(per_case, int) and per_case >= 1):
        raise ConfigError(f"per_case must be an integer >= 1, got {per_case!r}")
    scenarios, redrawn = [], 0
    for object_name, profile in itertools.product(objects, profiles):
        for i in range(per_case):
            scenario, redraws = draw_scenario(
                seed + i, "tuning", object_name, profile, plant="sim", duration=duration
            )
            scenarios.append(scenario)
            redrawn += redraws
    return scenarios, redrawn


def _gains(kp: float, kv: float, kx: float, base: PDGains) -> PDGains:
    return replace(base, kp=kp, kv=kv, kx_linear=kx, kx_angular=kx)


def evaluate_gains(gains: PDGains, episodes: list[Episode]) -> Candidate:
    """Run every episode with ``gains``; the mean tracking errors."""
    translation, angle = [], []
    for episode in episodes:
        episode.set_gains(gains)
        try:
            metrics = compute_metrics(episode.run())
        except PushctlError:  # a state that went non-finite: these gains are unstable
            return Candidate(gains, math.inf, math.inf, math.inf)
        translation.append(metrics.translation_error_pct)
        angle.append(metrics.angle_error_pct)
    t, a = float(np.mean(translation)), float(np.nanmean(angle))
    objective = t + a if math.isfinite(t + a) else math.inf
    return Candidate(gains, objective, t, a)


Point = tuple[float, float, float]
"""(K_p, K_v, K_x)."""

KP_FROM_ZERO = 30.0
"""The K_p tried next to a point with K_p = 0 [N·m/rad] (a factor cannot leave zero)."""


def neighbours(point: Point, factor: float) -> list[Point]:
    """The coordinate moves from ``point``: each gain times ``factor`` and divided by it;
    K_p also to 0 (or, from 0, to :data:`KP_FROM_ZERO`)."""
    kp, kv, kx = point
    moves = [(kp * factor, kv, kx), (kp / factor, kv, kx), (0.0, kv, kx)] if kp > 0.0 else []
    if kp == 0.0:
        moves.append((KP_FROM_ZERO, kv, kx))
    moves += [(kp, kv * factor, kx), (kp, kv / factor, kx)]
    moves += [(kp, kv, kx * factor), (kp, kv, kx / factor)]
    return moves


def tune_pd(
    scenarios: list[Scenario],
    base: PDGains | None = None,
    max_rounds: int = 6,
    grid: dict[str, tuple[float, ...]] | None = None,
    progress: Callable[[Candidate], None] | None = None,
) -> list[Candidate]:
    """Grid, then coordinate refinement (module doc). Returns every candidate evaluated,
    in order; the best is the one with the lowest objective (first on ties)."""
    base = base or PDGains()
    grid = grid or GRID
    episodes = [Episode(scenario, gains=base) for scenario in scenarios]
    seen: dict[Point, Candidate] = {}

    def score(point: Point) -> Point:
        kp, kv, kx = (float(np.clip(v, *BOUNDS[k])) for k, v in zip(BOUNDS, point, strict=True))
        clipped = (kp, kv, kx)
        if clipped not in seen:
            seen[clipped] = evaluate_gains(_gains(kp, kv, kx, base), episodes)
            if progress is not None:
                progress(seen[clipped])
        return clipped

    for point in itertools.product(grid["kp"], grid["kv"], grid["kx"]):
        score(point)
    best = min(seen, key=lambda p: seen[p].objective)
    factor = 2.0
    for _ in range(max_rounds):
        start = best
        for move in neighbours(start, factor):
            point = score(move)
            if seen[point].objective < seen[best].objective:
                best = point
        if best == start:
            factor = math.sqrt(factor)
            if factor < 1.1:
                break
    return list(seen.values())


def best_candidate(candidates: list[Candidate]) -> Candidate:
    """The lowest objective (the first evaluated on ties)."""
    return min(candidates, key=lambda candidate: candidate.objective)
