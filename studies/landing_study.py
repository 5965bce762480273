"""Why the feedback law's force error exceeds PD-only's (docs/plant-unknowns.md): the force
error of each controller against where the prongs landed on the face.

The approach aims at the object's *believed* pose, so a placement error across the face
lands the prongs that far from the plan's spot; no controller moves them back without
sliding. ``force_error``'s reference is the plant's needs with the prongs at the plan's
spot, so a push whose prongs landed d off it carries a force error that grows with |d|.
This study fits, per controller and cell, force error ≈ a + b·|d| over the tuning pushes
that did not fail, and reports the median force error of the pushes that landed within
0.5 mm of the spot.

All on the *tuning* stream (:func:`~pushctl.evaluation.tune_feedback.reset_pushes`).
``python -m studies.landing_study PLANT SEED PER_CASE`` prints the fit, then the
failed pushes with where they landed. ``python -m studies.landing_study
results/evaluation/trials.csv`` summarises an evaluation's landing offsets and its two
force errors per plant, cell and controller (:func:`landed_summary`).

``python -m studies.landing_study relanding PLANT SEED PER_CASE`` compares the
law's pushes from where the approach landed the prongs with the same pushes re-landed
(``EnvConfig.landing``, docs/plant-unknowns.md "Re-landing"), beside PD-only, per object
(:func:`relanding_pushes`, :func:`relanding_table`): the table of that section.
"""

from __future__ import annotations

import sys

import numpy as np
import pandas as pd

from pushctl.control.feedback import FeedbackGains, load_feedback_gains
from pushctl.episode.landed import landed
from pushctl.episode.metrics import compute_metrics, push_failed
from pushctl.episode.trace import Trace
from pushctl.evaluation.tune_feedback import BELIEVED, reset_pushes, tuning_env
from pushctl.objects import OBJECT_NAMES
from pushctl.planning import PROFILE_NAMES
from pushctl.rl.policy import pd_only_episode
from pushctl.task.env import PushEnv
from pushctl.task.env_config import EnvConfig
from studies.failure_study import finish_copy

NEAR_SPOT = 0.5e-3
"""[m]: a push whose prongs landed within this of the plan's spot is "on the spot"."""


def landing_pushes(plant: str, seed: int, per_case: int) -> pd.DataFrame:
    """Every tuning push of ``plant`` (seeds ``seed`` … ``seed + 6·per_case − 1``) under
    PD-only and the feedback law (the gains file's): controller, scenario seed, object,
    profile, where the prongs landed (:func:`~pushctl.episode.landed.landed`) [mm],
    force error [mN], and whether the push failed."""
    env = tuning_env(plant=plant, config=BELIEVED)
    reset = reset_pushes(env, seed, OBJECT_NAMES, PROFILE_NAMES, per_case)
    gains = load_feedback_gains()
    rows = []
    for member in reset:
        for controller in ("PD-only", "law"):
            trace = finish_copy(member, gains if controller == "law" else None)
            metrics = compute_metrics(trace)
            rows.append(
                {
                    "controller": controller,
                    "seed": member.scenario.seed,
                    "object": member.scenario.object,
                    "profile": member.scenario.profile,
                    "landed_mm": 1e3 * landed(trace),
                    "force_mN": 1e3 * metrics.force_error,
                    "failed": push_failed(metrics.translation_error_pct, metrics.angle_error_pct),
                }
            )
    return pd.DataFrame(rows)


RELANDING_CONTROLLERS = ("PD-only", "law, approach's landing", "law, re-landed")
"""The three pushes of every tuning scenario in :func:`relanding_pushes`, in table order."""


def relanding_pushes(
    plant: str, seed: int, per_case: int, gains: FeedbackGains | None = None
) -> pd.DataFrame:
    """Every tuning push of ``plant`` (seeds ``seed`` … ``seed + 6·per_case − 1``) three
    times: PD-only, the law (``gains``; default the gains file's) from where the approach
    landed the prongs (``landing = "believed"``), and the law re-landed (``"measured"``).
    PD-only is the measured environment's comparison push, which starts where the approach
    landed (:func:`~pushctl.rl.policy.pd_only_episode`; the same bytes under either setting).
    Rows: controller, seed, object, profile, translation and angle error [%], force error
    [mN], failed."""
    gains = gains or load_feedback_gains()
    pd_only, from_approach, relanded = RELANDING_CONTROLLERS
    rows = []
    for landing in ("believed", "measured"):
        env = tuning_env(plant=plant, config=EnvConfig(landing=landing))
        for reset in reset_pushes(env, seed, OBJECT_NAMES, PROFILE_NAMES, per_case):
            if landing == "believed":
                traces = [(from_approach, finish_copy(reset, gains))]
            else:  # the measured environment's PD-only push starts where the approach landed
                traces = [(pd_only, pd_only_episode(reset).finish()),
                          (relanded, finish_copy(reset, gains))]  # fmt: skip
            rows += [_push_row(controller, reset, trace) for controller, trace in traces]
    return pd.DataFrame(rows)


def _push_row(controller: str, reset: PushEnv, trace: Trace) -> dict:
    """One row of :func:`relanding_pushes`."""
    metrics = compute_metrics(trace)
    return {
        "controller": controller,
        "seed": reset.scenario.seed,
        "object": reset.scenario.object,
        "profile": reset.scenario.profile,
        "translation_pct": metrics.translation_error_pct,
        "angle_pct": metrics.angle_error_pct,
        "force_mN": 1e3 * metrics.force_error,
        "failed": push_failed(metrics.translation_error_pct, metrics.angle_error_pct),
    }


def relanding_table(pushes: pd.DataFrame) -> pd.DataFrame:
    """Per object and controller of :func:`relanding_pushes`' rows: the mean translation,
    angle and force errors over every push (failed ones included, as the evaluation's
    tables count them), and how many pushes failed of how many."""
    # a categorical column groups the controllers in table order, not alphabetically
    controller = pd.Categorical(pushes["controller"], categories=RELANDING_CONTROLLERS)
    grouped = pushes.assign(controller=controller).groupby(["object", "controller"], observed=True)
    table = grouped[["translation_pct", "angle_pct", "force_mN"]].mean()
    table["failed"] = grouped["failed"].sum()
    table["pushes"] = grouped.size()
    return table.reset_index().astype({"controller": str})


def landing_fit(pushes: pd.DataFrame) -> pd.DataFrame:
    """Per controller and cell, over the pushes of :func:`landing_pushes` that did not fail:
    the fit force ≈ a + b·|landed| (``a_mN``, ``b_mN_per_mm``), its correlation, and the
    median force error of the pushes landed within :data:`NEAR_SPOT` (and how many)."""
    rows = []
    kept = pushes[~pushes["failed"]]
    for (controller, obj, profile), group in kept.groupby(
        ["controller", "object", "profile"], sort=False
    ):
        distance = group["landed_mm"].abs().to_numpy()
        force = group["force_mN"].to_numpy()
        slope, intercept = np.polyfit(distance, force, 1)
        near = force[distance < 1e3 * NEAR_SPOT]
        rows.append(
            {
                "controller": controller,
                "object": obj,
                "profile": profile,
                "pushes": len(group),
                "a_mN": intercept,
                "b_mN_per_mm": slope,
                "correlation": float(np.corrcoef(distance, force)[0, 1]),
                "on_spot": len(near),
                "on_spot_median_mN": float(np.median(near)) if len(near) else np.nan,
            }
        )
    return pd.DataFrame(rows)


def landed_summary(trials: pd.DataFrame) -> pd.DataFrame:
    """Per plant, object, profile and controller of an evaluation's ``trials.csv`` rows (RL
    over every policy seed): the mean |landing offset| [mm], the share of pushes landed more
    than :data:`NEAR_SPOT` off, the correlation of the offset with −``placement_across`` (the
    approach aims at the believed pose, so the prongs land the other way), the mean
    ``force_error`` and ``force_error_landed`` [mN] and their ratio."""
    frame = trials.assign(
        landed_mm=1e3 * trials["landed_offset"].abs(),
        off_spot=trials["landed_offset"].abs() > NEAR_SPOT,
        force_mN=1e3 * trials["force_error"],
        force_landed_mN=1e3 * trials["force_error_landed"],
    )
    rows = []
    for key, group in frame.groupby(["plant", "object", "profile", "controller"], sort=False):
        rows.append(
            {
                **dict(zip(("plant", "object", "profile", "controller"), key, strict=True)),
                "landed_mm": group["landed_mm"].mean(),
                "off_spot_share": group["off_spot"].mean(),
                "r_placement": float(
                    np.corrcoef(group["landed_offset"], -group["placement_across"])[0, 1]
                ),
                "force_mN": group["force_mN"].mean(),
                "force_landed_mN": group["force_landed_mN"].mean(),
                "landed_over_plan_spot": group["force_landed_mN"].mean() / group["force_mN"].mean(),
            }
        )
    return pd.DataFrame(rows)


def main(argv: list[str]) -> None:  # pragma: no cover - prints the table
    pd.set_option("display.width", 200)
    if len(argv) == 1:
        trials = pd.read_csv(argv[0], comment="#")
        print(landed_summary(trials).round(3).to_string(index=False))
        return
    if argv[0] == "relanding":
        plant, seed, per_case = argv[1], int(argv[2]), int(argv[3])
        print(relanding_table(relanding_pushes(plant, seed, per_case)).round(3).to_string())
        return
    plant, seed, per_case = argv[0], int(argv[1]), int(argv[2])
    pushes = landing_pushes(plant, seed, per_case)
    print(landing_fit(pushes).round(2).to_string(index=False))
    print("\nfailed pushes:")
    print(pushes[pushes["failed"]].round(2).to_string(index=False))


if __name__ == "__main__":  # pragma: no cover
    main(sys.argv[1:])
