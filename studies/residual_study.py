"""The measurements behind the residual's defaults (docs/residual-and-feedback.md): how far
PD-only's object pose deviates from the plan with and without the plant unknowns, how fast
the feedback law asks the reference offset to grow (the action scale), and what the gate's
threshold costs, on the simulator (exact pose) and the proxy (the 30 Hz camera).

All on the *tuning* stream (the pushes of :func:`~pushctl.evaluation.tune_feedback.reset_pushes`),
never the evaluation's. ``python -m studies.residual_study`` prints the tables.
"""

from __future__ import annotations

import copy
from dataclasses import replace

import numpy as np
import pandas as pd

from pushctl.control.feedback import FeedbackGains, load_feedback_gains
from pushctl.episode.metrics import compute_metrics
from pushctl.episode.unknowns import NO_UNKNOWNS
from pushctl.evaluation.tune_feedback import BELIEVED, reset_pushes, tuning_env
from pushctl.objects import OBJECT_NAMES
from pushctl.planning import PROFILE_NAMES
from pushctl.rl.policy import finish_with_policy
from pushctl.task.env import PushEnv
from pushctl.task.feedback_actor import FeedbackActor

SIM_GATES = (0.0, 5e-5, 1e-4, 1.5e-4, 3e-4, 5e-4)
"""Gate thresholds [m] tried on the simulator."""
PROXY_GATES = (0.0, 1.5e-4, 1e-3, 2e-3, 3e-3)
"""Gate thresholds [m] tried on the proxy (its gate reads the camera, σ = 1 mm)."""


def pushes(plant: str, seed: int = 0, per_case: int = 2, unknowns: bool = True) -> list[PushEnv]:
    """The tuning pushes on ``plant``, reset; without the plant unknowns if not ``unknowns``."""
    env = tuning_env(plant=plant, config=BELIEVED)
    reset = reset_pushes(env, seed, OBJECT_NAMES, PROFILE_NAMES, per_case)
    if unknowns:
        return reset
    bare = []
    for member in reset:
        scenario = replace(member.scenario, unknowns=NO_UNKNOWNS)
        member.reset(options={"scenario": scenario})
        bare.append(copy.deepcopy(member))
    return bare


def pd_deviation(reset: list[PushEnv]) -> pd.DataFrame:
    """PD-only's gate deviation [mm] per push, as the gate reads it (camera on the proxy):
    its median and maximum over the push steps."""
    rows = []
    for member in reset:
        env = copy.deepcopy(member)
        assert env.episode is not None
        seen = []
        while not env.episode.done:
            env.advance(None if not env.gate_open else np.zeros(3))
            seen.append(env._deviation())
        values = 1e3 * np.array(seen)
        rows.append({"median_mm": np.median(values), "max_mm": values.max()})
    return pd.DataFrame(rows)


class _Recording(FeedbackActor):
    """The feedback actor, keeping the law's twist before the action's clip."""

    def __init__(self, env: PushEnv, gains: FeedbackGains) -> None:
        super().__init__(env, gains)
        self.twists: list[np.ndarray] = []

    def twist(self, observation: np.ndarray) -> np.ndarray:
        twist = super().twist(observation)
        self.twists.append(twist)
        return twist


def law_push(reset: list[PushEnv], gains: FeedbackGains, gate: float) -> pd.DataFrame:
    """The feedback law with ``gate`` [m] on every push: the metrics, the gate's open share,
    and the law's unclipped twist (99th percentile and maximum of |v| [mm/s], |ω| [rad/s])."""
    rows = []
    for member in reset:
        env = copy.deepcopy(member)
        env.config = replace(env.config, gate_threshold=gate)
        assert env.episode is not None
        actor = _Recording(env, gains)
        opened = finish_with_policy(env, actor)
        metrics = compute_metrics(env.episode.trace())
        twists = np.array(actor.twists) if actor.twists else np.zeros((1, 3))
        speed = 1e3 * np.hypot(twists[:, 0], twists[:, 1])
        rows.append(
            {
                "translation_pct": metrics.translation_error_pct,
                "angle_pct": metrics.angle_error_pct,
                "open": opened / env.episode.n_steps,
                "v99_mm_s": np.percentile(speed, 99),
                "v_max_mm_s": speed.max(),
                "w99_rad_s": np.percentile(np.abs(twists[:, 2]), 99),
            }
        )
    return pd.DataFrame(rows)


def gate_table(
    reset: list[PushEnv], gains: FeedbackGains, gates: tuple[float, ...]
) -> pd.DataFrame:
    """Means over the pushes of :func:`law_push` per gate threshold, PD-only first."""
    pd_only = pd.DataFrame(
        [compute_metrics(copy.deepcopy(m).episode.finish()).as_dict() for m in reset]  # type: ignore[union-attr]
    )
    rows = [
        {
            "gate_mm": "PD-only",
            "translation_pct": pd_only["translation_error_pct"].mean(),
            "angle_pct": np.nanmean(pd_only["angle_error_pct"]),
        }
    ]
    for gate in gates:
        frame = law_push(reset, gains, gate)
        rows.append(
            {
                "gate_mm": f"{1e3 * gate:g}",
                "translation_pct": frame["translation_pct"].mean(),
                "angle_pct": np.nanmean(frame["angle_pct"]),
                "open": frame["open"].mean(),
                "v99_mm_s": frame["v99_mm_s"].max(),
                "v_max_mm_s": frame["v_max_mm_s"].max(),
                "w99_rad_s": frame["w99_rad_s"].max(),
            }
        )
    return pd.DataFrame(rows)


def main(gains_file: str | None = None) -> None:  # pragma: no cover - prints the tables
    gains = load_feedback_gains(gains_file)
    pd.set_option("display.width", 160)
    for plant, gates in (("sim", SIM_GATES), ("proxy", PROXY_GATES)):
        with_unknowns = pushes(plant)
        print(f"== {plant}: PD-only gate deviation [mm] without / with the unknowns")
        print(pd_deviation(pushes(plant, unknowns=False)).describe().loc[["50%", "max"]])
        print(pd_deviation(with_unknowns).describe().loc[["50%", "max"]])
        print(f"== {plant}: feedback {gains} by gate threshold")
        print(gate_table(with_unknowns, gains, gates).to_string(index=False))


if __name__ == "__main__":  # pragma: no cover
    import sys

    main(sys.argv[1] if len(sys.argv) > 1 else None)
