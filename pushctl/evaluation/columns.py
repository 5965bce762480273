"""The columns of ``pushctl evaluate``'s CSVs, in a module of their own that imports nothing,
so that :mod:`pushctl.report` can check its inputs against them without loading the
simulator or torch."""

UNKNOWN_COLUMNS = (
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
    "ground_length",
    "ground_seed",
)
"""The plant unknowns of a trial (:meth:`pushctl.episode.unknowns.PlantUnknowns.as_dict` of
the two-prong pusher): SI units and radians; ``pressure_*`` are fractions of the half-extents,
``ground_variation`` of μ_g."""

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
    *UNKNOWN_COLUMNS,
    "gate_open_fraction",
    "landed_offset",
    "force_error_landed",
)
"""The leading columns of ``trials.csv``; the :class:`EpisodeMetrics` fields follow.
``landed_offset`` [m]: where the prongs landed across the face against the plan's spot;
``force_error_landed`` [N]: the force error against the plant's needs with the prongs there
(:mod:`pushctl.episode.landed`)."""

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

TRIALS_FILE = "trials.csv"
"""The evaluation's per-trial table, in its output directory."""
STEPS_FILE = "steps.csv"
"""The evaluation's per-step means, in its output directory."""
