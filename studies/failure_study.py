"""The measurements behind the feedback law's settings (docs/residual-and-feedback.md): its
offset bound and sideways cap, turn cap, output lag, contact-seeking turn, contact threshold
and slide guard: PD-only and the law under each setting on one larger tuning set, per object, with
the pushes that fail counted apart.

All on the *tuning* stream (:func:`~pushctl.evaluation.tune_feedback.reset_pushes`, tuning
seeds ``seed`` … ``seed + 6·per_case − 1``), never the evaluation's; the gains are
``pushctl/defaults/feedback_gains.toml``'s k and k_i whatever the setting, or the ``K`` and
``K_I`` given. ``python -m studies.failure_study ...`` prints:

- ``[SEED] [PER_CASE] [K K_I]``: the bounds' table (:data:`SETTINGS`; about ten minutes at
  the defaults on one core);
- ``turn [SEED PER_CASE K K_I]``: the turn cap's (:data:`TURN_SETTINGS`);
- ``smoothing PLANT [SEED PER_CASE K K_I]``: the output lag's on ``PLANT``;
- ``seek PLANT [SEED PER_CASE K K_I]``: the contact-seeking turn's rate on ``PLANT``
  (:data:`SEEK_SETTINGS`);
- ``contact PLANT [SEED PER_CASE K K_I]``: the contact threshold and the offset's yaw bound
  on ``PLANT`` (:data:`CONTACT_SETTINGS`);
- ``slide PLANT [SEED PER_CASE K K_I]``: the slide guard's limit and lag on ``PLANT``
  (:data:`SLIDE_SETTINGS`);
- ``ringing [SEED]``: what a command alternating every step does to each engine's contact
  (:func:`ringing`);
- ``split PLANT OBJECT PROFILE SEED [SEED ...]``: where PD-only's and the law's force error
  goes late in a push (:func:`force_split`, docs/plant-unknowns.md);
- ``gains PLANT SEED PER_CASE K K_I [K K_I ...]``: today's law at several gains against
  PD-only per cell (:func:`gain_table`).
"""

from __future__ import annotations

import copy
import itertools
import math
import sys
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
import pandas as pd

from pushctl.control.feedback import FeedbackGains, load_feedback_gains
from pushctl.episode.landed import landed
from pushctl.episode.metrics import compute_metrics, push_failed
from pushctl.episode.trace import Trace
from pushctl.evaluation.tune_feedback import BELIEVED, reset_pushes, tuning_env
from pushctl.objects import OBJECT_NAMES
from pushctl.planning import PROFILE_NAMES
from pushctl.rl.policy import finish_with_policy
from pushctl.task.env import PushEnv
from pushctl.task.feedback_actor import FeedbackActor


@dataclass(frozen=True)
class Setting:
    """One row of the study: the law with ``lateral_ratio``, ``hold_off_contact``,
    ``seek_rate``, ``turn_ratio``, ``smoothing``, ``seek_ramp``, ``contact_force`` [N],
    ``slide_limit`` [m] and ``slide_filter`` [s] under the offset bound (``linear`` [m],
    ``angular`` [deg]); ``law`` False: PD-only."""

    name: str
    law: bool = True
    linear: float = math.inf
    angular_deg: float = math.inf
    lateral_ratio: float = math.inf
    hold_off_contact: bool = True
    seek_rate: float = 0.0
    turn_ratio: float = math.inf
    smoothing: float = 0.0
    seek_ramp: float = 0.0
    contact_force: float = 0.01  # the first five passes' threshold
    slide_limit: float = math.inf  # the first six passes had no slide guard
    slide_filter: float = 1.0


LAW_FIELDS = (
    "lateral_ratio",
    "hold_off_contact",
    "seek_rate",
    "turn_ratio",
    "smoothing",
    "seek_ramp",
    "contact_force",
    "slide_limit",
    "slide_filter",
)
"""The settings a :class:`Setting` and :class:`FeedbackGains` share (the rest of a row's law
is the gains' k and k_i)."""

SETTINGS = (
    Setting("PD-only", law=False),
    Setting("law, offset unbounded"),
    Setting("+ offset bound 5 mm, 3 deg", linear=0.005, angular_deg=3.0),
    Setting("+ offset bound 8 mm, 5 deg", linear=0.008, angular_deg=5.0),
    Setting("+ offset bound 3 mm, 1.5 deg", linear=0.003, angular_deg=1.5),
    Setting("3 mm, 1.5 deg + sideways cap 0.15", True, 0.003, 1.5, 0.15),
    Setting("3 mm, 1.5 deg + sideways cap 0.05", True, 0.003, 1.5, 0.05),
    Setting("3 mm, 1.5 deg + sideways cap 0.02", True, 0.003, 1.5, 0.02),
    Setting("3 mm, 1.5 deg + no sideways correction", True, 0.003, 1.5, 0.0),
    Setting("3 mm, 1.5 deg, acting off contact", True, 0.003, 1.5, hold_off_contact=False),
    Setting("3 mm, 1.5 deg, cap 0.05 + seeking 0.005 rad/s", True, 0.003, 1.5, 0.05, True, 0.005),
    Setting("3 mm, 1.5 deg, cap 0.05 + seeking 0.01 rad/s", True, 0.003, 1.5, 0.05, True, 0.01),
    Setting("3 mm, 1.5 deg, cap 0.05 + seeking 0.02 rad/s", True, 0.003, 1.5, 0.05, True, 0.02),
    Setting("3 mm, 1.5 deg, cap 0.05 + seeking 0.05 rad/s", True, 0.003, 1.5, 0.05, True, 0.05),
)
"""The rows of the bounds' table (offset bound, sideways cap, seeking), in its order."""

_BOUNDED_LAW = (True, 0.003, 1.5, 0.05, True, 0.01)
TURN_SETTINGS = (
    Setting("PD-only", law=False),
    Setting("bounded law, turn uncapped", *_BOUNDED_LAW),
    *(
        Setting(f"+ turn cap {ratio:g}", *_BOUNDED_LAW, turn_ratio=ratio)
        for ratio in (0.2, 0.1, 0.05, 0.03)
    ),
)
"""The rows of the turn cap's table (``failure_study turn``): the bounded law (3 mm,
1.5 deg, sideways cap 0.05, seeking 0.01 rad/s) at each cap."""

SMOOTHING_SETTINGS = (
    Setting("PD-only", law=False),
    *(
        Setting(f"turn cap 0.05, lag {tau:g} s", *_BOUNDED_LAW, 0.05, tau)
        for tau in (0.0, 0.03, 0.1, 0.3)
    ),
)
"""The rows of the output lag's table (``failure_study smoothing PLANT``)."""

SEEK_SETTINGS = (
    Setting("PD-only", law=False),
    *(  # the law with turn cap 0.05, lag 0.1 s at each seeking rate and ramp
        Setting(
            f"seeking {rate:g} rad/s, ramp {ramp:g} s",
            *_BOUNDED_LAW[:5],
            seek_rate=rate,
            turn_ratio=0.05,
            smoothing=0.1,
            seek_ramp=ramp,
        )
        for rate, ramp in ((0.01, 0.0), (0.03, 0.0), (0.1, 0.0), (0.1, 0.2))
    ),
)
"""The rows of the seeking turn's table (``failure_study seek PLANT``)."""

CONTACT_SETTINGS = (
    Setting("PD-only", law=False),
    *(  # the ramped fast seek at each contact threshold and yaw bound
        replace(
            SEEK_SETTINGS[4],
            name=f"{1e3 * force:g} mN, yaw bound {angular:g} deg",
            angular_deg=angular,
            contact_force=force,
        )
        for force, angular in ((0.01, 1.5), (0.05, 1.5), (0.01, 3.0), (0.05, 3.0), (0.05, 5.0))
    ),
)
"""The rows of the contact threshold's table (``failure_study contact PLANT``)."""

SLIDE_SETTINGS = (
    Setting("PD-only", law=False),
    replace(CONTACT_SETTINGS[4], name="50 mN, 3 deg law, no slide guard"),
    *(  # the law at 50 mN, 3 deg with the guard at each limit and lag
        replace(
            CONTACT_SETTINGS[4],
            name=f"slide guard {1e3 * limit:g} mm, lag {lag:g} s",
            slide_limit=limit,
            slide_filter=lag,
        )
        for limit, lag in ((0.0005, 0.0), (0.0005, 1.0), (0.0005, 2.0), (0.001, 1.0))
    ),
)
"""The rows of the slide guard's table (``failure_study slide PLANT``)."""


def push_all(reset: list[PushEnv], setting: Setting, gains: FeedbackGains) -> pd.DataFrame:
    """Every push of ``reset`` (a copy of it) under ``setting``: object, translation and
    angle error [%], and whether it failed."""
    rows = []
    for member in reset:
        trace = finish_setting(member, setting, gains)
        metrics = compute_metrics(trace)
        rows.append(
            {
                "object": member.scenario.object,
                "profile": member.scenario.profile,
                "translation_pct": metrics.translation_error_pct,
                "angle_pct": metrics.angle_error_pct,
                "force_error": metrics.force_error,
                "contact_loss": metrics.contact_loss_fraction,
            }
        )
    frame = pd.DataFrame(rows)
    frame["failed"] = push_failed(frame["translation_pct"], frame["angle_pct"])
    return frame


def study(
    seed: int = 1000,
    per_case: int = 20,
    settings: tuple[Setting, ...] = SETTINGS,
    gains: FeedbackGains | None = None,
    plant: str = "sim",
) -> pd.DataFrame:
    """One row per setting: per object, the mean translation and angle errors [%], the
    number of failed pushes and the share of steps with a prong off the face, on
    ``plant``'s tuning pushes. ``gains``: k and k_i (default: the gains file's)."""
    env = tuning_env(plant=plant, config=BELIEVED)
    reset = reset_pushes(env, seed, OBJECT_NAMES, PROFILE_NAMES, per_case)
    gains = gains or load_feedback_gains()
    rows = []
    for setting in settings:
        frame = push_all(reset, setting, gains)
        row: dict[str, object] = {"setting": setting.name}
        for name, group in frame.groupby("object", sort=False):
            row[f"{name}_translation_pct"] = group["translation_pct"].mean()
            row[f"{name}_angle_pct"] = np.nanmean(group["angle_pct"])
            row[f"{name}_failed"] = int(group["failed"].sum())
            row[f"{name}_contact_loss"] = group["contact_loss"].mean()
            row[f"{name}_force_mN"] = 1e3 * group["force_error"].mean()
        rows.append(row)
    return pd.DataFrame(rows)


def gain_table(
    plant: str, seed: int, per_case: int, gains: list[tuple[float, float]]
) -> pd.DataFrame:
    """PD-only and today's law (the defaults of ``pushctl/defaults/feedback_gains.toml`` and
    :class:`EnvConfig`) at each (k, k_i) of ``gains`` on ``plant``'s tuning pushes: per
    object × profile, the means of translation and angle error [%], force error [N] and
    contact-loss share."""
    env = tuning_env(plant=plant, config=BELIEVED)
    reset = reset_pushes(env, seed, OBJECT_NAMES, PROFILE_NAMES, per_case)
    base = load_feedback_gains()
    bound = (env.config.offset_limit_linear, math.degrees(env.config.offset_limit_angular))
    fields = {name: getattr(base, name) for name in LAW_FIELDS}
    law = Setting("law", linear=bound[0], angular_deg=bound[1], **fields)
    frames = [push_all(reset, Setting("PD-only", law=False), base).assign(controller="PD-only")]
    for k, k_i in gains:
        frame = push_all(reset, law, replace(base, k=k, k_i=k_i))
        frames.append(frame.assign(controller=f"k {k:.3g}, k_i {k_i:.3g}"))
    columns = ["translation_pct", "angle_pct", "force_error", "contact_loss"]
    frame = pd.concat(frames)
    return frame.groupby(["controller", "object", "profile"], sort=False)[columns].mean()


def finish_copy(
    reset: PushEnv, law: FeedbackGains | None, offset_limit: tuple[float, float] | None = None
) -> Trace:
    """The trace of a copy of the ``reset`` push run to its end under PD-only (``law``
    None) or the feedback law with ``law``'s gains, under ``offset_limit`` (linear [m],
    angular [rad]; None: the environment's) (``reset`` itself is not advanced)."""
    push = copy.deepcopy(reset)
    episode = push.episode
    assert episode is not None
    if law is None:
        return episode.finish()
    if offset_limit is not None:
        episode.set_offset_limit(offset_limit)
    finish_with_policy(push, FeedbackActor(push, law))
    return episode.trace()


def finish_setting(reset: PushEnv, setting: Setting, gains: FeedbackGains) -> Trace:
    """:func:`finish_copy` under ``setting``: PD-only, or the law with ``gains``' k and k_i
    and the setting's other fields, under its offset bound."""
    if not setting.law:
        return finish_copy(reset, None)
    law = replace(gains, **{name: getattr(setting, name) for name in LAW_FIELDS})
    return finish_copy(reset, law, (setting.linear, math.radians(setting.angular_deg)))


def force_split(
    plant: str, object_name: str, profile: str, seeds: list[int], after: float = 4.0
) -> pd.DataFrame:
    """Where PD-only's and today's law's force error goes on the tuning pushes of ``seeds``
    (``object_name``, ``profile``, ``plant``), from ``after`` [s] into the push to its end:
    per push and controller, each prong's mean signed normal-force error (measured minus
    the plant's needs) [mN], the total normal force's [mN] and the contact torque's
    [mN·m] (docs/plant-unknowns.md: an equal and opposite split with the right total and
    torque is what a contact spot across the face other than the reference's gives); and
    before ``after``, the force error as the metric has it (mean over steps and prongs of
    the force vector's error) [mN]; and where the prongs landed across the face
    (:func:`landed`) [mm]."""
    env = tuning_env(plant=plant, config=BELIEVED)
    gains = load_feedback_gains()
    rows = []
    for seed in seeds:
        env.reset(options={"object": object_name, "profile": profile, "scenario_seed": seed})
        for controller in ("PD-only", "law"):
            trace = finish_copy(env, gains if controller == "law" else None)
            t = np.asarray(trace.t)
            late = t >= after
            early = ~late & (t > 0.0)  # the metrics skip the first row too
            error = np.asarray(trace.contact_forces) - np.asarray(trace.desired_forces)
            normal = error[late, :, 0]
            torque = np.asarray(trace.contact_torque) - np.asarray(trace.desired_torque)
            row: dict[str, object] = {"seed": seed, "controller": controller}
            row["landed_mm"] = 1e3 * landed(trace)
            for prong, mean in enumerate(normal.mean(axis=0), start=1):
                row[f"normal_{prong}_mN"] = 1e3 * mean
            row["total_normal_mN"] = 1e3 * normal.sum(axis=1).mean()
            row["torque_mNm"] = 1e3 * torque[late].mean()
            row["force_error_before_mN"] = 1e3 * np.linalg.norm(error[early], axis=-1).mean()
            rows.append(row)
    return pd.DataFrame(rows)


SEEK_ACTION = np.array([0.07, 0.0, -0.2], dtype=np.float32)
"""The law's seek twist (0.35 mm/s, 10 mrad/s) as an action at the default action scale."""


def ringing(seed: int = 1000) -> pd.DataFrame:
    """The share of steps with a prong off the face on one cube push (tuning seed ``seed``,
    constant profile) on ``sim`` and ``mujoco``: PD-only, the seek twist held, and the seek
    twist alternating with zero every step (what the law's mode switches do)."""
    rows = []
    for plant in ("sim", "mujoco"):
        env = tuning_env(plant=plant, config=BELIEVED)
        reset = reset_pushes(env, seed, ("cube",), ("constant",), 1)[0]
        policies = {
            "PD-only": None,
            "seek twist held": lambda _obs: SEEK_ACTION,
            "seek twist alternating with zero": _alternating(SEEK_ACTION),
        }
        for name, policy in policies.items():
            push = copy.deepcopy(reset)
            assert push.episode is not None
            if policy is None:
                trace = push.episode.finish()
            else:
                finish_with_policy(push, policy)
                trace = push.episode.trace()
            loss = compute_metrics(trace).contact_loss_fraction
            rows.append({"plant": plant, "command": name, "contact_loss": loss})
    return pd.DataFrame(rows)


def _alternating(action: np.ndarray) -> Callable[[np.ndarray], np.ndarray]:
    """A policy that returns ``action`` on its 1st, 3rd, ... call and zero on the others."""
    calls = itertools.count()
    return lambda _obs: action * float(next(calls) % 2 == 0)


def main(argv: list[str]) -> None:  # pragma: no cover - prints the table
    pd.set_option("display.width", 200)
    if argv and argv[0] == "gains":  # gains PLANT SEED PER_CASE K K_I [K K_I ...]
        plant, seed, per_case = argv[1], int(argv[2]), int(argv[3])
        values = [float(v) for v in argv[4:]]
        pairs = list(zip(values[::2], values[1::2], strict=True))
        print(gain_table(plant, seed, per_case, pairs).round(3).to_string())
        return
    if argv and argv[0] == "split":  # split PLANT OBJECT PROFILE SEED [SEED ...]
        seeds = [int(a) for a in argv[4:]]
        print(force_split(argv[1], argv[2], argv[3], seeds).round(2).to_string(index=False))
        return
    if argv and argv[0] == "ringing":  # ringing [SEED]
        print(ringing(*(int(a) for a in argv[1:2])).round(4).to_string(index=False))
        return
    settings: tuple[Setting, ...] = SETTINGS
    plant = "sim"
    if argv and argv[0] == "turn":  # turn [SEED PER_CASE K K_I]
        settings, argv = TURN_SETTINGS, argv[1:]
    elif argv and argv[0] == "smoothing":  # smoothing PLANT [SEED PER_CASE K K_I]
        settings, plant, argv = SMOOTHING_SETTINGS, argv[1], argv[2:]
    elif argv and argv[0] == "seek":  # seek PLANT [SEED PER_CASE K K_I]
        settings, plant, argv = SEEK_SETTINGS, argv[1], argv[2:]
    elif argv and argv[0] == "contact":  # contact PLANT [SEED PER_CASE K K_I]
        settings, plant, argv = CONTACT_SETTINGS, argv[1], argv[2:]
    elif argv and argv[0] == "slide":  # slide PLANT [SEED PER_CASE K K_I]
        settings, plant, argv = SLIDE_SETTINGS, argv[1], argv[2:]
    seed = int(argv[0]) if argv else 1000
    per_case = int(argv[1]) if len(argv) > 1 else 20
    gains = None
    if len(argv) > 3:
        gains = replace(load_feedback_gains(), k=float(argv[2]), k_i=float(argv[3]))
    pd.set_option("display.width", 200)
    print(study(seed, per_case, settings, gains, plant).round(3).to_string(index=False))


if __name__ == "__main__":  # pragma: no cover
    main(sys.argv[1:])
