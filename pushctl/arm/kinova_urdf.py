"""The project's URDF of the Kinova Gen2 7-DOF spherical-wrist arm (j2s7s300).

Written from the published kinematic and inertial figures collected in
docs/kinova-facts.md §1 (joints), §2 (link inertials), §3 (fingers), never from a copied
file. Modelling choices:

- The continuous joints 1, 3, 5, 7 are written ``revolute`` with ±2π limits, so that
  ``nq == nv == 7`` and a configuration is a plain vector of joint angles [rad].
- The three-finger hand is rigid: the six finger links (§3, all finger joints at 0) are
  lumped into ``link_7`` together with its own 0.99 kg inertial (§2), by the parallel-axis
  theorem with each finger inertia rotated through its rpy chain. Total mass is then
  5.55724 kg, of which 5.08940 kg moves (docs/kinova-facts.md §6, "incl. 6 finger links").
- No visual or collision geometry: the dynamics need none.

Regenerate the shipped file with ``python -m pushctl.arm.kinova_urdf``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

PREFIX = "j2s7s300_"
TWO_PI = 2.0 * math.pi
PI = math.pi
HALF_PI = 0.5 * math.pi

URDF_FILENAME = "kinova_gen2_7dof.urdf"
"""Name of the shipped file in ``pushctl/arm/data``."""


@dataclass(frozen=True)
class JointRow:
    """One row of docs/kinova-facts.md §1: a joint from ``parent`` to ``child``.

    ``xyz`` [m] and ``rpy`` [rad] place the child frame in the parent frame; the axis is the
    child frame's z. Limits: position [rad], effort [N·m], velocity [rad/s].
    """

    name: str
    parent: str
    child: str
    xyz: tuple[float, float, float]
    rpy: tuple[float, float, float]
    lower: float
    upper: float
    effort: float
    velocity: float


@dataclass(frozen=True)
class LinkInertial:
    """One row of docs/kinova-facts.md §2: mass [kg], CoM [m] in the link frame, principal
    inertia [kg·m²] about the CoM in link-frame axes (products of inertia are zero)."""

    name: str
    mass: float
    com: tuple[float, float, float]
    diag: tuple[float, float, float]


# docs/kinova-facts.md §1. Continuous joints (1, 3, 5, 7) carry the ±2π limits of the xacro.
ARM_JOINTS: tuple[JointRow, ...] = (
    JointRow("joint_1", "link_base", "link_1", (0, 0, 0.15675), (0, PI, 0),
             -TWO_PI, TWO_PI, 40.0, 0.628319),
    JointRow("joint_2", "link_1", "link_2", (0, 0.0016, -0.11875), (-HALF_PI, 0, PI),
             0.820305, 5.462881, 80.0, 0.628319),
    JointRow("joint_3", "link_2", "link_3", (0, -0.205, 0), (-HALF_PI, 0, 0),
             -TWO_PI, TWO_PI, 40.0, 0.628319),
    JointRow("joint_4", "link_3", "link_4", (0, 0, -0.205), (HALF_PI, 0, PI),
             0.523599, 5.759587, 40.0, 0.628319),
    JointRow("joint_5", "link_4", "link_5", (0, 0.2073, -0.0114), (-HALF_PI, 0, PI),
             -TWO_PI, TWO_PI, 20.0, 0.837758),
    JointRow("joint_6", "link_5", "link_6", (0, 0, -0.10375), (HALF_PI, 0, PI),
             1.134464, 5.148721, 20.0, 0.837758),
    JointRow("joint_7", "link_6", "link_7", (0, 0.10375, 0), (-HALF_PI, 0, PI),
             -TWO_PI, TWO_PI, 20.0, 0.837758),
)  # fmt: skip

# docs/kinova-facts.md §1, fixed joint link_7 → end_effector.
END_EFFECTOR_XYZ = (0.0, 0.0, -0.16)
END_EFFECTOR_RPY = (PI, 0.0, HALF_PI)

# docs/kinova-facts.md §2.
LINK_INERTIALS: tuple[LinkInertial, ...] = (
    LinkInertial("link_base", 0.46784, (0, 0, 0.1255),
                 (9.512708616e-04, 9.512708616e-04, 3.742720000e-04)),
    LinkInertial("link_1", 0.7477, (0, -0.002, -0.0605),
                 (1.520317252e-03, 1.520317252e-03, 5.981600000e-04)),
    LinkInertial("link_2", 0.8447, (0, -0.103563213, 0),
                 (2.470737617e-03, 3.801150000e-04, 2.470737617e-03)),
    LinkInertial("link_3", 0.8447, (0, 0, -0.1022447445),
                 (2.470737617e-03, 2.470737617e-03, 3.801150000e-04)),
    LinkInertial("link_4", 0.6763, (0, 0.081, -0.0086),
                 (1.420224319e-03, 3.043350000e-04, 1.420224319e-03)),
    LinkInertial("link_5", 0.463, (0, 0.0028848942, -0.0541932613),
                 (4.321316048e-04, 4.321316048e-04, 9.260000000e-05)),
    LinkInertial("link_6", 0.463, (0, 0.0497208855, -0.0028562765),
                 (4.321316048e-04, 9.260000000e-05, 4.321316048e-04)),
    LinkInertial("link_7", 0.99, (0, 0, -0.06),
                 (3.453236187e-04, 3.453236187e-04, 5.816000000e-04)),
)  # fmt: skip

# docs/kinova-facts.md §3: every finger link (proximal and distal) has this inertial in its
# own frame.
FINGER_LINK = LinkInertial("finger", 0.01, (0.022, 0, 0), (7.8999684e-07, 7.8999684e-07, 8e-08))
# Finger base frames on link_7: (xyz [m], rpy [rad]); the proximal joint sits there at 0 rad.
FINGER_BASES: tuple[tuple[tuple[float, float, float], tuple[float, float, float]], ...] = (
    ((0.00279, 0.03126, -0.11467), (-1.7047873384941834, 0.6476144647144773, 1.67317415161155)),
    ((0.02226, -0.02707, -0.11482), (-1.570796327, 0.649262481663582, -1.38614049188413)),
    ((-0.02226, -0.02707, -0.11482), (-1.570796327, 0.649262481663582, -1.75545216211587)),
)
# Distal joint origin in the proximal frame (rpy 0), distal joint at 0 rad.
DISTAL_XYZ = (0.044, -0.003, 0.0)


def rpy_to_matrix(rpy: tuple[float, float, float]) -> np.ndarray:
    """URDF fixed-axis roll-pitch-yaw to a rotation matrix, R = Rz(y)·Ry(p)·Rx(r), (3, 3)."""
    r, p, y = rpy
    cr, sr, cp, sp, cy, sy = (math.cos(r), math.sin(r), math.cos(p), math.sin(p),
                              math.cos(y), math.sin(y))  # fmt: skip
    rot_x = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    rot_y = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rot_z = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return rot_z @ rot_y @ rot_x


def _finger_links_in_link7() -> list[tuple[np.ndarray, np.ndarray]]:
    """Pose of each of the six finger-link frames in link_7: list of (R (3, 3), p (3,) [m])."""
    poses = []
    for xyz, rpy in FINGER_BASES:
        rot_prox, pos_prox = rpy_to_matrix(rpy), np.array(xyz, dtype=float)
        poses.append((rot_prox, pos_prox))
        poses.append((rot_prox, pos_prox + rot_prox @ np.array(DISTAL_XYZ)))
    return poses


def lumped_hand_inertial() -> tuple[float, np.ndarray, np.ndarray]:
    """link_7's own inertial plus the six rigid finger links, as one body in link_7's frame.

    Returns ``(mass [kg], com (3,) [m], inertia (3, 3) [kg·m²] about com, link_7 axes)``.
    """
    hand = LINK_INERTIALS[-1]
    bodies = [(hand.mass, np.array(hand.com, dtype=float), np.diag(hand.diag))]
    finger_inertia = np.diag(FINGER_LINK.diag)
    for rot, pos in _finger_links_in_link7():
        com = pos + rot @ np.array(FINGER_LINK.com)
        bodies.append((FINGER_LINK.mass, com, rot @ finger_inertia @ rot.T))
    mass = float(sum(m for m, _, _ in bodies))
    com = np.sum([m * c for m, c, _ in bodies], axis=0) / mass
    inertia = np.zeros((3, 3))
    for m, c, inertia_c in bodies:
        d = c - com  # parallel-axis shift from the body's CoM to the lumped CoM
        inertia += inertia_c + m * (d @ d * np.eye(3) - np.outer(d, d))
    return mass, com, 0.5 * (inertia + inertia.T)


def _num(x: float) -> str:
    """Twelve significant digits: exact for the FACTS figures, immune to last-bit noise."""
    text = f"{float(x):.12g}"
    return "0" if text == "-0" else text


def _vec(values) -> str:
    return " ".join(_num(v) for v in values)


def _link_xml(name: str, mass: float, com, inertia: np.ndarray) -> str:
    i = inertia
    return (
        f'  <link name="{PREFIX}{name}">\n'
        f"    <inertial>\n"
        f'      <origin xyz="{_vec(com)}" rpy="0 0 0"/>\n'
        f'      <mass value="{_num(mass)}"/>\n'
        f'      <inertia ixx="{_num(i[0, 0])}" ixy="{_num(i[0, 1])}" ixz="{_num(i[0, 2])}" '
        f'iyy="{_num(i[1, 1])}" iyz="{_num(i[1, 2])}" izz="{_num(i[2, 2])}"/>\n'
        f"    </inertial>\n"
        f"  </link>\n"
    )


def _joint_xml(row: JointRow) -> str:
    return (
        f'  <joint name="{PREFIX}{row.name}" type="revolute">\n'
        f'    <parent link="{PREFIX}{row.parent}"/>\n'
        f'    <child link="{PREFIX}{row.child}"/>\n'
        f'    <origin xyz="{_vec(row.xyz)}" rpy="{_vec(row.rpy)}"/>\n'
        f'    <axis xyz="0 0 1"/>\n'
        f'    <limit lower="{_num(row.lower)}" upper="{_num(row.upper)}" '
        f'effort="{_num(row.effort)}" velocity="{_num(row.velocity)}"/>\n'
        f'    <dynamics damping="0" friction="0"/>\n'
        f"  </joint>\n"
    )


def _fixed_joint_xml(name: str, parent: str, child: str, xyz, rpy) -> str:
    return (
        f'  <joint name="{PREFIX}{name}" type="fixed">\n'
        f'    <parent link="{parent}"/>\n'
        f'    <child link="{PREFIX}{child}"/>\n'
        f'    <origin xyz="{_vec(xyz)}" rpy="{_vec(rpy)}"/>\n'
        f"  </joint>\n"
    )


def kinova_gen2_7dof_urdf() -> str:
    """The URDF text of the j2s7s300 arm with its rigid three-finger hand lumped into link_7."""
    parts = [
        '<?xml version="1.0"?>\n',
        "<!-- Generated by pushctl.arm.kinova_urdf from the published Kinova Gen2 j2s7s300\n"
        "     figures (shared/kinova/FACTS.md). Do not edit: run\n"
        "     python -m pushctl.arm.kinova_urdf -->\n",
        '<robot name="j2s7s300">\n',
        '  <link name="root"/>\n',
        _fixed_joint_xml("joint_base", "root", "link_base", (0, 0, 0), (0, 0, 0)),
    ]
    for link in LINK_INERTIALS[:-1]:
        parts.append(_link_xml(link.name, link.mass, link.com, np.diag(link.diag)))
    parts.append(_link_xml("link_7", *lumped_hand_inertial()))
    parts.extend(_joint_xml(row) for row in ARM_JOINTS)
    parts.append(f'  <link name="{PREFIX}end_effector"/>\n')
    parts.append(
        _fixed_joint_xml(
            "joint_end_effector",
            f"{PREFIX}link_7",
            "end_effector",
            END_EFFECTOR_XYZ,
            END_EFFECTOR_RPY,
        )
    )
    parts.append("</robot>\n")
    return "".join(parts)


def shipped_urdf_path() -> Path:
    """Source-tree path of the shipped URDF (for regeneration; loaders use importlib)."""
    return Path(__file__).resolve().parent / "data" / URDF_FILENAME


def write_shipped_urdf() -> None:
    """Regenerate ``pushctl/arm/data/kinova_gen2_7dof.urdf``."""
    path = shipped_urdf_path()
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(kinova_gen2_7dof_urdf(), encoding="utf-8")
