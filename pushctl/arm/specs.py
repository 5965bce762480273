"""The selectable arms: where each model comes from and its documented defaults.

Every arm is loaded as a Pinocchio model whose configuration is a plain vector of joint
angles (``nq == nv``), with the hand rigid (fingers locked or lumped) and no free-flyer.

Sources
    ``kinova-gen2-7dof``: the project's own URDF (:mod:`pushctl.arm.kinova_urdf`), read as
    package data. ``kinova-j2s6s200`` and ``panda``: the URDFs of the installed
    example-robot-data distribution, found through ``importlib.metadata`` (its 6.x wheels
    ship the robot files without a Python module). Continuous joints are read as revolute
    with ±2π limits; the Panda's two finger joints are locked at 0.

Ready configuration
    The pusher frame at ``ready_position`` with its axes on the world axes, solved by
    :func:`pushctl.arm.ik.solve_frame_ik` from ``seed_q``. Kinova 7-DOF: (0.30, 0, 0.06) m,
    seeded with docs/kinova-facts.md §7 pose A; holding the tool down at this height its pusher
    reaches x ≈ 0.25–0.70 m for yaws up to ±45° (cond J ≤ 25 there), which covers objects
    starting at x ≈ 0.40–0.45 m and pushed 0.25 m further. j2s6s200: same target, seeded with
    the analogue of pose A (end effector at (0.55, 0, 0.045), tool down, elbow up). Panda: see
    ``PANDA_READY_PUSHER_POSITION``, seeded with the srdf "default" pose.

Joint armature (reflected rotor inertia) [kg·m²]
    None of the three manufacturers publishes rotor inertias, so the defaults are estimates:

    - Kinova Gen2 (``kinova-gen2-7dof``, ``kinova-j2s6s200``): armature = N²·J_rotor with the
      transmission reduction N = 160 (docs/kinova-facts.md §1) and an estimated rotor inertia
      for the two actuator sizes: J_rotor ≈ 5.0e-6 kg·m² for the large KA-75+ actuators (40/80 N·m
      joints) and ≈ 2.0e-6 kg·m² for the small KA-58 ones (20 N·m joints), the order of
      magnitude of the flat brushless motors that fit those housings. This gives 0.128 and
      0.0512 kg·m²; treat them as uncertain by a factor of about three.
    - Panda: 0.1 kg·m² on every joint. example-robot-data ships no rotor parameters for
      it; 0.1 is the value commonly used in simulation models of the Panda (for example the
      MuJoCo Menagerie description), not a Franka figure.

Viscous joint damping [N·m·s/rad]
    Kinova: 0, as in the published description (docs/kinova-facts.md §1, "damping 0").
    Panda: 0.003, the ``<dynamics damping>`` of the example-robot-data URDF.
"""

from __future__ import annotations

import importlib.metadata
import importlib.resources
import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from pushctl.arm.kinova_urdf import URDF_FILENAME
from pushctl.errors import ConfigError

ARM_NAMES = ("kinova-gen2-7dof", "kinova-j2s6s200", "panda")
"""Names accepted by ``ArmConfig.name``; the first is the default (the paper's arm)."""

KINOVA_REDUCTION = 160.0
"""Kinova Gen2 transmission reduction N [-] (docs/kinova-facts.md §1)."""
KINOVA_ROTOR_LARGE = 5.0e-6
"""Estimated rotor inertia of a large (KA-75+) Kinova actuator [kg·m²]."""
KINOVA_ROTOR_SMALL = 2.0e-6
"""Estimated rotor inertia of a small (KA-58) Kinova actuator [kg·m²]."""
KINOVA_ARMATURE_LARGE = KINOVA_REDUCTION**2 * KINOVA_ROTOR_LARGE
KINOVA_ARMATURE_SMALL = KINOVA_REDUCTION**2 * KINOVA_ROTOR_SMALL
PANDA_ARMATURE = 0.1
PANDA_DAMPING = 0.003

READY_PUSHER_POSITION = (0.30, 0.0, 0.06)
"""Pusher-frame origin (prong midpoint) of the ready configuration, world [m]."""

PANDA_READY_PUSHER_POSITION = (0.35, 0.0, 0.06)
"""The Panda's ready pusher position, world [m]. Holding the tool down at this height the
Panda folds its elbow (joint 4) onto its −3.07 rad limit for x < 0.31 m, and (0.30, 0, 0.06)
is out of reach; at x = 0.35 m joint 4 keeps 0.15 rad of travel and cond(J) ≈ 13. Place the
object so its pushed face is beyond 0.36 m."""

_ERD_DISTRIBUTION = "example-robot-data"


@dataclass(frozen=True)
class ArmSpec:
    """How to build one arm and where its pusher hangs.

    ``push_axis_ee`` and ``tool_axis_ee`` are unit axes of the end-effector frame
    ``ee_frame``: the tool axis points from the wrist out through the tool (world −z in the
    ready pose), the push axis is the end-effector axis that points along world +x in the
    tool-down seed. ``seed_q`` (nq,) [rad] seeds the ready-pose inverse kinematics and is its
    posture reference. ``armature`` [kg·m²] and ``damping`` [N·m·s/rad] are the defaults.
    """

    name: str
    nv: int
    ee_frame: str
    push_axis_ee: tuple[int, int, int]
    tool_axis_ee: tuple[int, int, int]
    seed_q: tuple[float, ...]
    armature: tuple[float, ...]
    damping: tuple[float, ...]
    build: Callable[[], pin.Model]
    ready_position: tuple[float, float, float] = READY_PUSHER_POSITION


def _build_kinova_gen2_7dof() -> pin.Model:
    """The project's own j2s7s300 URDF, read from the installed package data."""
    resource = importlib.resources.files("pushctl.arm") / "data" / URDF_FILENAME
    return pin.buildModelFromXML(resource.read_text(encoding="utf-8"))


def _example_robot_data_file(suffix: str) -> Path:
    """Locate a file of the installed example-robot-data distribution by its path suffix."""
    try:
        dist = importlib.metadata.distribution(_ERD_DISTRIBUTION)
    except importlib.metadata.PackageNotFoundError as exc:
        raise ConfigError(
            "this arm needs the example-robot-data package (pip install example-robot-data)"
        ) from exc
    for file in dist.files or ():
        if str(file).replace("\\", "/").endswith(suffix):
            return Path(str(dist.locate_file(file)))
    raise ConfigError(f"example-robot-data has no file ending in {suffix!r}")


def _build_kinova_j2s6s200() -> pin.Model:
    """example-robot-data's Jaco2 6-DOF (fingers already fixed in its URDF).

    Its continuous joints are read as revolute with the ±2π limits the file already gives,
    so that ``nq == nv == 6``.
    """
    path = _example_robot_data_file("kinova_description/robots/kinova.urdf")
    text = path.read_text(encoding="utf-8").replace('type="continuous"', 'type="revolute"')
    return pin.buildModelFromXML(text)


def _build_panda() -> pin.Model:
    """example-robot-data's Panda with the hand's two finger joints locked at 0 (closed)."""
    path = _example_robot_data_file("panda_description/urdf/panda.urdf")
    full = pin.buildModelFromXML(path.read_text(encoding="utf-8"))
    fingers = [full.getJointId(n) for n in ("panda_finger_joint1", "panda_finger_joint2")]
    return pin.buildReducedModel(full, fingers, pin.neutral(full))


_L, _S = KINOVA_ARMATURE_LARGE, KINOVA_ARMATURE_SMALL

ARM_SPECS: dict[str, ArmSpec] = {
    # EE frame at docs/kinova-facts.md §7 pose A: y_ee ≈ world +x, z_ee = world −z (tool down).
    "kinova-gen2-7dof": ArmSpec(
        name="kinova-gen2-7dof",
        nv=7,
        ee_frame="j2s7s300_end_effector",
        push_axis_ee=(0, 1, 0),
        tool_axis_ee=(0, 0, 1),
        seed_q=(0.0049, 2.2236, 3.1751, 1.7228, 3.1047, 2.3362, 6.2757),
        armature=(_L, _L, _L, _L, _S, _S, _S),
        damping=(0.0,) * 7,
        build=_build_kinova_gen2_7dof,
    ),
    # This URDF's end-effector frame (rpy π, π/2, 0 on link_6) has x along the tool; the
    # push axis is link_6's +x, as link_7's +x is for the 7-DOF arm, i.e. −z_ee. The seed is
    # the analogue of pose A (EE at (0.55, 0, 0.045), pusher axes on the world axes), solved
    # once with solve_frame_ik and rounded; q1 ≈ −π/2 undoes the mounting block's +π/2 yaw.
    "kinova-j2s6s200": ArmSpec(
        name="kinova-j2s6s200",
        nv=6,
        ee_frame="j2s6s200_end_effector",
        push_axis_ee=(0, 0, -1),
        tool_axis_ee=(1, 0, 0),
        seed_q=(-1.5530, 4.0599, 1.7229, -3.1416, 2.3370, 0.0178),
        armature=(_L, _L, _L, _S, _S, _S),
        damping=(0.0,) * 6,
        build=_build_kinova_j2s6s200,
    ),
    # panda_hand_tcp (between the fingertips) in the srdf "default" pose: x = world +x,
    # z = world −z.
    "panda": ArmSpec(
        name="panda",
        nv=7,
        ee_frame="panda_hand_tcp",
        push_axis_ee=(1, 0, 0),
        tool_axis_ee=(0, 0, 1),
        seed_q=(0.0, -math.pi / 4, 0.0, -3 * math.pi / 4, 0.0, math.pi / 2, math.pi / 4),
        armature=(PANDA_ARMATURE,) * 7,
        damping=(PANDA_DAMPING,) * 7,
        build=_build_panda,
        ready_position=PANDA_READY_PUSHER_POSITION,
    ),
}


def arm_spec(name: str) -> ArmSpec:
    """The spec of arm ``name``; ConfigError listing ARM_NAMES if unknown."""
    try:
        return ARM_SPECS[name]
    except (KeyError, TypeError):
        raise ConfigError(f"unknown arm {name!r}; choose one of {', '.join(ARM_NAMES)}") from None


def check_spec_model(spec: ArmSpec, model: pin.Model) -> None:
    """Guard against a changed upstream description: angles-only, finite limits, right nv."""
    if model.nq != spec.nv or model.nv != spec.nv:
        raise ConfigError(
            f"arm {spec.name!r} loaded with nq={model.nq}, nv={model.nv}; expected {spec.nv}"
        )
    limits = np.concatenate([model.lowerPositionLimit, model.upperPositionLimit])
    if not np.all(np.isfinite(limits)):
        raise ConfigError(f"arm {spec.name!r} has a joint without finite position limits")
