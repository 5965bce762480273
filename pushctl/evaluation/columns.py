"""The columns of ``pushctl evaluate``'s CSVs, in a module of their own that imports nothing,
so that :mod:`pushctl.report` can check its inputs against them without loading the
simulator or torch."""

TRIAL_COLUMNS = (
    "object",
    "profile",
    "plant",
    "controller",
    "trial",
    "seed",
    "policy_seed",
    "redrawn",
    "goal_dx",
    "goal_dy",
    "goal_dtheta",
    "mu_ground",
    "mu_contact",
    "object_mass",
    "pusher_mass",
    "gate_open_fraction",
)
"""The leading columns of ``trials.csv``; the :class:`EpisodeMetrics` fields follow."""

STEP_COLUMNS = (
    "translation_des_mm",
    "translation_mm",
    "angle_des_deg",
    "angle_deg",
    "translation_error_mm",
    "angle_error_deg",
    "force_error",
    "torque_error",
)
"""The per-step quantities of ``steps.csv``
(see :func:`~pushctl.evaluation.trials.step_quantities`)."""
