"""``pushctl tune-feedback``: the feedback baseline's gains (k, k_i), chosen by a documented
search on the tuning stream (docs/design.md §5; never on the evaluation set).

The procedure:

1. Tuning set: for every object × profile (case c = 0 … 5 in the order of
   :data:`~pushctl.objects.OBJECT_NAMES` × :data:`~pushctl.planning.PROFILE_NAMES`),
   ``per_case`` scenarios of the *tuning* stream, scenario seeds ``seed + c·per_case + i``
   (every push its own goal and unknowns), on the ``sim`` plant, the plant the policy trains
   on, and (``pushctl tune-feedback --plant both``, the default) the same seeds again on the
   ``proxy``, whose 30 Hz camera noise (σ 1 mm, 0.5°) a high gain integrates into the
   reference offset; with everything a reset draws there (goal, parameters and the plant
   unknowns the planner cannot see). Each is reset once; every candidate pushes from a copy
   of the episode as the approach left it, so all candidates see the same pushes.
2. The push: the feedback law (:class:`~pushctl.task.feedback_actor.FeedbackActor`)
   through the environment's gate, action scale and residual path: today's defaults of
   :class:`~pushctl.task.env_config.EnvConfig`, the settings ``pushctl evaluate`` runs it with.
3. Objective: the mean over the tuning set of translation error % + angle error %
   (docs/design.md §7), as for the PD gains; a push that fails (a non-finite state) scores
   infinity.
4. Search: the grid :data:`GRID` of (k, k_i), then a refinement of the best point, each gain
   times and divided by 2 and then by √2 (:data:`REFINE_FACTORS`). PD-only (k = k_i = 0) is
   scored beside them for the record.
"""

from __future__ import annotations

import copy
import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from pushctl.control.feedback import FeedbackGains
from pushctl.episode.metrics import compute_metrics
from pushctl.errors import ConfigError, PushctlError
from pushctl.rl.policy import finish_with_policy, pd_only_episode
from pushctl.task.env import PushEnv
from pushctl.task.env_config import EnvConfig
from pushctl.task.feedback_actor import FeedbackActor

GRID = {"k": (0.1, 0.2, 0.35, 0.5), "k_i": (0.0, 0.02, 0.05, 0.1)}
"""The coarse grid: k [1/s] × k_i [1/s²], 16 candidates (docs/design.md §5's prototype: k = 0.5 /s
helped, k ≥ 1 /s lost the wedge's turning pushes)."""
REFINE_FACTORS = (2.0, math.sqrt(2.0))
"""Refinement: each gain of the best point times and divided by these, in turn."""
K_I_FROM_ZERO = 0.01
"""The k_i tried next to a best point with k_i = 0 [1/s²] (a factor cannot leave zero)."""


@dataclass(frozen=True)
class FeedbackCandidate:
    """One gain pair and its means over the tuning set: translation error [%], angle error
    [%] (over pushes that turn), their sum (the objective), and the gate's open share."""

    k: float
    k_i: float
    objective: float
    translation_error_pct: float
    angle_error_pct: float
    gate_open_fraction: float


BELIEVED = EnvConfig(landing="believed")
"""The studies' environment (``failure_study``, ``landing_study``, ``residual_study``): the
law's pushes start where the approach landed the prongs, as in the passes they document,
which came before the re-landing (docs/plant-unknowns.md, "Re-landing")."""


def tuning_env(
    duration: float = 20.0, plant: str = "sim", config: EnvConfig | None = None
) -> PushEnv:
    """The environment of the tuning pushes: ``config`` (default :class:`EnvConfig`'s
    residual settings) on the tuning stream with ``plant``'s ranges."""
    base = config or EnvConfig()
    return PushEnv(replace(base, stream="tuning", plant=plant, duration=duration))


def reset_pushes(
    env: PushEnv, seed: int, objects: tuple[str, ...], profiles: tuple[str, ...], per_case: int
) -> list[PushEnv]:
    """The tuning set, each push reset (approach run) in a copy of ``env``."""
    if not (isinstance(per_case, int) and per_case >= 1):
        raise ConfigError(f"--per-case must be an integer >= 1, got {per_case!r}")
    pushes = []
    for case, (object_name, profile) in enumerate(itertools.product(objects, profiles)):
        for i in range(per_case):
            options = {"object": object_name, "profile": profile}
            env.reset(options={**options, "scenario_seed": seed + case * per_case + i})
            pushes.append(copy.deepcopy(env))
    return pushes


def score(gains: FeedbackGains | None, pushes: list[PushEnv]) -> FeedbackCandidate:
    """Push every member of the tuning set (a copy of it) with the law of ``gains`` (None:
    PD-only) and average the metrics."""
    translation, angle, opened = [], [], []
    for reset in pushes:
        env = copy.deepcopy(reset)
        assert env.episode is not None
        try:
            if gains is None:
                trace = pd_only_episode(env).finish()
                share = 0.0
            else:
                share = finish_with_policy(env, FeedbackActor(env, gains)) / env.episode.n_steps
                trace = env.episode.trace()
            metrics = compute_metrics(trace)
        except PushctlError:  # a state that went non-finite
            k, k_i = (0.0, 0.0) if gains is None else (gains.k, gains.k_i)
            return FeedbackCandidate(k, k_i, math.inf, math.inf, math.inf, math.nan)
        translation.append(metrics.translation_error_pct)
        angle.append(metrics.angle_error_pct)
        opened.append(share)
    t, a = float(np.mean(translation)), float(np.nanmean(angle))
    k, k_i = (0.0, 0.0) if gains is None else (gains.k, gains.k_i)
    objective = t + a if math.isfinite(t + a) else math.inf
    return FeedbackCandidate(k, k_i, objective, t, a, float(np.mean(opened)))


def tune_feedback(
    pushes: list[PushEnv],
    base: FeedbackGains | None = None,
    progress: Callable[[FeedbackCandidate], None] | None = None,
) -> list[FeedbackCandidate]:
    """Grid, then refinement (module doc). Returns every candidate in the order scored;
    the best is the lowest objective (first on ties)."""
    base = base or FeedbackGains()
    seen: dict[tuple[float, float], FeedbackCandidate] = {}

    def visit(k: float, k_i: float) -> None:
        point = (float(k), float(k_i))
        if point not in seen and k > 0.0:
            seen[point] = score(replace(base, k=point[0], k_i=point[1]), pushes)
            if progress is not None:
                progress(seen[point])

    for k, k_i in itertools.product(GRID["k"], GRID["k_i"]):
        visit(k, k_i)
    for factor in REFINE_FACTORS:
        improved = True
        while improved:
            best = min(seen, key=lambda p: seen[p].objective)
            k, k_i = best
            moves = [(k * factor, k_i), (k / factor, k_i)]
            moves += [(k, k_i * factor), (k, k_i / factor)] if k_i > 0 else [(k, K_I_FROM_ZERO)]
            for move in moves:
                visit(*move)
            improved = min(seen, key=lambda p: seen[p].objective) != best
    return list(seen.values())


def best_feedback(candidates: list[FeedbackCandidate]) -> FeedbackCandidate:
    """The lowest objective (the first scored on ties)."""
    return min(candidates, key=lambda candidate: candidate.objective)


def feedback_toml(
    best: FeedbackCandidate,
    pd_only: FeedbackCandidate,
    candidates: list[FeedbackCandidate],
    search: dict[str, object],
    header: str,
    base: FeedbackGains,
) -> str:
    """The gains file: ``header`` as comments, ``[feedback]`` (``best``'s gains and
    ``base``'s other settings) and ``[search]`` (``search``'s entries, PD-only's score and
    every candidate as [k, k_i, objective, translation %, angle %])."""
    record = {
        **search,
        "candidates_evaluated": len(candidates),
        "best_objective": best.objective,
        "best_translation_error_pct": best.translation_error_pct,
        "best_angle_error_pct": best.angle_error_pct,
        "best_gate_open_fraction": best.gate_open_fraction,
        "pd_only_objective": pd_only.objective,
        "pd_only_translation_error_pct": pd_only.translation_error_pct,
        "pd_only_angle_error_pct": pd_only.angle_error_pct,
        "grid_k": list(GRID["k"]),
        "grid_k_i": list(GRID["k_i"]),
        "candidates_k_ki_objective_translation_angle": [
            [c.k, c.k_i, c.objective, c.translation_error_pct, c.angle_error_pct]
            for c in candidates
        ],
    }
    lines = [f"# {line}" for line in header.splitlines()]
    lines += ["", "[feedback]", f"k = {best.k!r}", f"k_i = {best.k_i!r}"]
    lines += [f"contact_force = {base.contact_force!r}"]
    lines += [f"hold_off_contact = {_toml(base.hold_off_contact)}"]
    lines += [f"lateral_ratio = {_toml(float(base.lateral_ratio))}"]
    lines += [f"seek_rate = {_toml(float(base.seek_rate))}"]
    lines += [f"seek_ramp = {_toml(float(base.seek_ramp))}"]
    lines += [f"turn_ratio = {_toml(float(base.turn_ratio))}"]
    lines += [f"smoothing = {_toml(float(base.smoothing))}"]
    lines += [f"slide_limit = {_toml(float(base.slide_limit))}"]
    lines += [f"slide_filter = {_toml(float(base.slide_filter))}", "", "[search]"]
    lines += [f"{key} = {_toml(value)}" for key, value in record.items()]
    return "\n".join(lines) + "\n"


def _toml(value: object) -> str:
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value) if math.isfinite(value) else ("nan" if math.isnan(value) else "inf")
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_toml(item) for item in value) + "]"
    return repr(value)
