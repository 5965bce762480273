"""The push environment's observation and action, as tables of index, name, meaning, unit and
scale. The environment builds its vectors in this order and the tables of docs/learning.md
are made from here (:func:`markdown_table`; tests/task/test_env.py checks the copies), so the
documentation cannot drift from the code.

Frames: "plan frame" is the planned object frame at the current step (x along the push into
the object, the pushed face's normal at θ = 0; y to its left), so the same correction means
the same thing whatever the goal's heading. ``scale`` is a typical magnitude: the learner
divides by it (``obs_scale``), and it is what a value of 1 means to the networks. Each is
sized so that the row's 95th percentile of |value| / scale over PD-only and feedback-law
pushes is between about 0.1 and 2 (tests/task/test_env.py checks PD-only's): the pose error
by 2 mm and 0.02 rad, where PD-only's reach 1.2-1.8 mm and 0.017 rad. A policy keeps the
scales it was trained with (its ``obs_scale``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from pushctl.errors import ConfigError


@dataclass(frozen=True)
class Entry:
    """One row: ``name`` (snake case, the index key), ``meaning``, ``unit``, ``scale``."""

    name: str
    meaning: str
    unit: str
    scale: float


def observation_entries(
    n_prongs: int, reference_offset: bool = False, context: bool = False
) -> tuple[Entry, ...]:
    """The observation's rows for a pusher with ``n_prongs`` prongs (all deployable: the
    planned forces come from the nominal plan, the measured ones from the contact model, or a
    force estimate on a real arm). ``reference_offset``: add the offset the ``reference``
    residual path has built so far (the controller's own state: the actor integrates it, so
    without it the same observation can call for opposite corrections). ``context``
    (``EnvConfig.observe_context``): add the pose error's rate, the plan's speed and the base
    law's output (zero without one), before the phase."""
    forces = (
        ("force_n_des", "planned normal force", "next step"),
        ("force_t_des", "planned tangential force", "next step"),
        ("force_n", "measured normal force", "last step"),
        ("force_t", "measured tangential force", "last step"),
    )
    rows = [
        Entry(f"{name}_{i}", f"{meaning}, prong {i}, {when}", "N", 0.5)
        for name, meaning, when in forces
        for i in range(1, n_prongs + 1)
    ]
    rows += [
        Entry("pusher_vx", "pusher velocity along the push (plan frame x)", "m/s", 0.01),
        Entry("pusher_vy", "pusher velocity across the push (plan frame y)", "m/s", 0.01),
        Entry("pusher_wz", "pusher yaw rate", "rad/s", 0.05),
        Entry("error_x", "planned minus actual object position, plan frame x", "m", 2e-3),
        Entry("error_y", "planned minus actual object position, plan frame y", "m", 2e-3),
        Entry("error_theta", "planned minus actual object heading", "rad", 2e-2),
    ]
    if reference_offset:
        rows += [
            Entry("offset_x", "pusher reference offset built so far, plan frame x", "m", 1e-3),
            Entry("offset_y", "pusher reference offset built so far, plan frame y", "m", 1e-3),
            Entry("offset_theta", "pusher reference yaw offset built so far", "rad", 2e-2),
        ]
    if context:
        rows += CONTEXT_ENTRIES
    rows.append(Entry("phase", "push steps taken / push steps (0 … 1)", "1", 1.0))
    return tuple(rows)


CONTEXT_ENTRIES: tuple[Entry, ...] = (
    Entry("error_rate_x", "rate of error_x, through a 0.1 s lag", "m/s", 1e-3),
    Entry("error_rate_y", "rate of error_y, through a 0.1 s lag", "m/s", 1e-3),
    Entry("error_rate_theta", "rate of error_theta, through a 0.1 s lag", "rad/s", 1e-2),
    Entry("plan_speed", "the plan's object speed now (the law's caps scale with it)", "m/s", 1e-2),
    Entry("law_x", "the base law's last action along the push (plan frame x)", "× scale", 0.1),
    Entry("law_y", "the base law's last action across the push (plan frame y)", "× scale", 0.1),
    Entry("law_wz", "the base law's last yaw-rate action", "× scale", 0.1),
)
"""The rows ``EnvConfig.observe_context`` adds: how fast the pose error closes, how far the
law's caps reach (they scale with the plan's speed), and how much of the envelope the law
already uses (its action before the policy's is added, clipped to [−1, 1])."""

ACTION_ENTRIES: tuple[Entry, ...] = (
    Entry("residual_x", "residual pusher velocity along the push (plan frame x)", "× scale", 1.0),
    Entry("residual_y", "residual pusher velocity across the push (plan frame y)", "× scale", 1.0),
    Entry("residual_wz", "residual pusher yaw rate", "× scale", 1.0),
)
"""The action, each in [−1, 1]: × ``action_scale_linear`` [m/s] (x, y) or
``action_scale_angular`` [rad/s] (ω_z), rotated from the plan frame to the world and added
to the PD's commanded pusher twist while the gate is open (Algorithm 1)."""


def clipped_action(x: float, y: float, w: float) -> tuple[float, float, float]:
    """An action's three floats clipped to the action space's [−1, 1]: the floats
    ``np.clip`` gives (a −0.0 kept), without an array (the environment and the feedback law
    clip every 10 ms step)."""
    return (min(max(x, -1.0), 1.0), min(max(y, -1.0), 1.0), min(max(w, -1.0), 1.0))


def action_floats(action: Any) -> list[float]:
    """step()'s ``action`` as three Python floats (a float32 entry converted exactly, as
    ``np.asarray(action, dtype=float)`` does); ConfigError unless 3 finite numbers."""
    # The usual float32 or float64 array: its list's sum is finite unless an entry is not
    # (or the sum overflows: the full check then decides), without asarray and
    # isfinite(...).all().
    if type(action) is np.ndarray and action.shape == (3,) and action.dtype.char in "fd":
        values = action.tolist()
        if math.isfinite(sum(values)):
            return values
    array = np.asarray(action, dtype=float)
    if array.shape != (3,) or not np.all(np.isfinite(array)):
        raise ConfigError(f"action must be 3 finite numbers in [-1, 1], got {array!r}")
    return array.tolist()


PRIVILEGED_KEYS = (
    "placement_along",
    "placement_across",
    "placement_theta",
    "mount_yaw",
    "prong_1_along",
    "prong_1_across",
    "prong_2_along",
    "prong_2_across",
    "pressure_n",
    "pressure_t",
    "ground_variation",
)
"""The plant unknowns a privileged critic sees (docs/plant-unknowns.md), in order; 0 where a
scenario lacks one."""

PRIVILEGED_SCALES = np.array(
    [1e-3, 1e-3, 1e-2, 1e-2, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 0.1, 0.5, 0.5, 0.5]
    + [2e-3, 2e-3, 2e-2]
)
"""The typical sizes [SI] the critic divides
:meth:`~pushctl.task.env.PushEnv.privileged_state`'s rows by: the unknowns of
docs/plant-unknowns.md (``placement_*``, ``mount_yaw``, the prongs' ``*_along``/``*_across``,
``pressure_*``, ``ground_variation``), μ_ground, μ_contact, the object's mass [kg], and the
exact pose error (e_x, e_y [m], e_θ [rad])."""


def index(entries: tuple[Entry, ...]) -> dict[str, int]:
    """Name → position."""
    return {entry.name: i for i, entry in enumerate(entries)}


def scales(entries: tuple[Entry, ...]) -> np.ndarray:
    """The ``scale`` column (d,)."""
    return np.array([entry.scale for entry in entries])


def markdown_table(entries: tuple[Entry, ...]) -> str:
    """The rows as a Markdown table: index, name, meaning, unit, scale."""
    lines = ["| index | name | meaning | unit | scale |", "|---|---|---|---|---|"]
    lines += [
        f"| {i} | `{e.name}` | {e.meaning} | {e.unit} | {e.scale:g} |"
        for i, e in enumerate(entries)
    ]
    return "\n".join(lines)
