"""Cross-engine validation: our world and the MuJoCo world against physics and each other.

Each case runs on both engines (``make_world(engine=...)``) and returns plain numbers:

- :func:`free_slide`: an object launched at v0 stops after v0²/(2 μ_g g) (axis, diagonal);
- :func:`spin_down`: an object spun at ω0 on its corner supports stops after
  ω0²/(2 α), α = μ_g m g r̄ / I_z (r̄ the mean corner distance from the centre of mass);
- :func:`rest`: an object left at rest: pose drift (creep) and how far it sinks;
- :func:`straight_push`: the PD pushing the cube straight on a planned push: cruise Σλ_n
  against μ_g m g, its chatter, and the prongs' deepest penetration;
- :func:`arc_push`: one planned arc push per object and profile on both engines: pose and
  force differences between the engines.

``python -m studies.mujoco_validation [--docs docs/mujoco.md]`` prints the Markdown table
and, with ``--docs``, rewrites the generated block of that page.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

from pushctl.config import GRAVITY
from pushctl.engines import ENGINES, make_world
from pushctl.episode.metrics import compute_metrics
from pushctl.episode.runner import Episode
from pushctl.episode.scenario import Scenario
from pushctl.episode.trace import Trace
from pushctl.files.provenance import write_atomic
from pushctl.types import PlanarPose

MU_GROUND = 0.3
SLIDE_SPEED = 0.5  # [m/s]
SPIN_CASES = ((3.0, 1e-3), (10.0, 0.01))
"""Spin-downs (ω0 [rad/s], h [s]): the cube stops in 21 ms and in 71 ms."""
ARC_GOAL = PlanarPose.from_degrees(0.60, 0.03, 25.0)
"""The arc pushes' goal from the default start (0.42, 0, 0): 18 cm forward, 3 cm left, 25°."""
STRAIGHT_GOAL = PlanarPose(0.62, 0.0, 0.0)
PROFILES = ("constant", "trapezoid", "chirp")
OBJECTS = ("cube", "wedge")
BEGIN, END = "<!-- BEGIN validation table -->", "<!-- END validation table -->"


def _run_until_rest(world, max_steps: int = 5000) -> np.ndarray:
    """Step an object-only world until it stops (speed < 1e-6); the final pose (3,)."""
    result = None
    for _ in range(max_steps):
        result = world.step()
        if np.abs(result.object_velocity).max() < 1e-6:
            break
    assert result is not None
    return result.object_pose


def free_slide(engine: str, heading_deg: float, obj: str = "cube") -> dict[str, float]:
    """Distance [m] slid from v0 = SLIDE_SPEED along ``heading_deg`` (object at θ = 0), the
    analytic v0²/(2 μ g), and the heading's drift [rad]."""
    world = make_world(obj, arm=None, mu_ground=MU_GROUND, engine=engine)
    heading = math.radians(heading_deg)
    v = (SLIDE_SPEED * math.cos(heading), SLIDE_SPEED * math.sin(heading), 0.0)
    world.reset(object_pose=(0.0, 0.0, 0.0), object_velocity=v)
    final = _run_until_rest(world)
    expected = SLIDE_SPEED**2 / (2.0 * MU_GROUND * GRAVITY)
    direction = math.atan2(final[1], final[0])
    return {
        "distance": float(np.hypot(final[0], final[1])),
        "expected": expected,
        "direction_error": abs(direction - heading),
        "theta": float(final[2]),
    }


def spin_down(engine: str, omega0: float, dt: float, obj: str = "cube") -> dict[str, float]:
    """Angle [rad] turned from ω0 [rad/s] on the spot with step dt [s], and the analytic
    angle for friction at the footprint's corners (our support points, MuJoCo's box–plane
    contacts)."""
    world = make_world(obj, arm=None, mu_ground=MU_GROUND, dt=dt, engine=engine)
    world.reset(object_pose=(0.0, 0.0, 0.0), object_velocity=(0.0, 0.0, omega0))
    final = _run_until_rest(world)
    spec = world.object
    loads = spec.support_loads  # [N] at GRAVITY
    torque = MU_GROUND * float(loads @ np.linalg.norm(np.asarray(spec.support_points), axis=1))
    expected = omega0**2 / (2.0 * torque / spec.inertia_z)
    return {"angle": float(final[2]), "expected": expected, "drift": float(np.hypot(*final[:2]))}


def rest(engine: str, obj: str = "cube", seconds: float = 5.0) -> dict[str, float]:
    """An object left at rest for ``seconds``: its largest pose drift [m, rad] and, on
    MuJoCo, how deep it sinks into the soft floor [m]."""
    world = make_world(obj, arm=None, mu_ground=MU_GROUND, engine=engine)
    start = np.array([0.4, 0.1, 0.3])
    world.reset(object_pose=start)
    drift = 0.0
    for _ in range(round(seconds / world.config.dt)):
        result = world.step()
        drift = max(drift, float(np.abs(result.object_pose - start).max()))
    sink = -getattr(world, "object_height", 0.0)
    return {"drift": drift, "sink": sink}


def _episode(engine: str, obj: str, profile: str, goal: PlanarPose) -> Trace:
    episode = Episode(Scenario(object=obj, profile=profile, goal=goal), engine=engine)
    return episode.run()


def straight_push(engine: str, obj: str = "cube") -> dict[str, float]:
    """The PD on a planned straight 20 cm push at constant speed: Σλ_n over the cruise
    (the middle 80 % of the push) against μ_g m g [N], its spread, and the deepest prong
    penetration [m]."""
    trace = _episode(engine, obj, "constant", STRAIGHT_GOAL)
    total = trace.contact_forces[:, :, 0].sum(axis=1)
    n = len(total)
    cruise = total[n // 10 : n - n // 10]
    return {
        "mean": float(cruise.mean()),
        "min": float(cruise.min()),
        "max": float(cruise.max()),
        "std": float(cruise.std()),
        "expected": MU_GROUND * 0.300 * GRAVITY,
        "penetration": float(max(0.0, -trace.prong_gaps.min())),
        "distance": float(trace.object_pose[-1, 0] - trace.object_pose[0, 0]),
    }


def arc_push(obj: str, profile: str) -> dict[str, float]:
    """One planned arc push on both engines, same plan and PD: the engines' pose
    differences (RMS and final, [m] and [rad]), mean |Σλ_n difference| [N], each engine's
    force error [N] (against the plant's needs) and deepest penetration [m]."""
    ours, theirs = (_episode(engine, obj, profile, ARC_GOAL) for engine in ENGINES)
    dpose = theirs.object_pose - ours.object_pose
    dpos = np.hypot(dpose[:, 0], dpose[:, 1])
    dforce = theirs.contact_forces[:, :, 0].sum(1) - ours.contact_forces[:, :, 0].sum(1)
    m_ours, m_mj = compute_metrics(ours), compute_metrics(theirs)
    return {
        "rms_position": float(np.sqrt(np.mean(dpos**2))),
        "final_position": float(dpos[-1]),
        "rms_angle": float(np.sqrt(np.mean(dpose[:, 2] ** 2))),
        "final_angle": float(abs(dpose[-1, 2])),
        "force_difference": float(np.mean(np.abs(dforce))),
        "force_error_ours": m_ours.force_error,
        "force_error_mujoco": m_mj.force_error,
        "penetration_ours": m_ours.max_penetration,
        "penetration_mujoco": m_mj.max_penetration,
        "translation_error_ours": m_ours.translation_error_pct,
        "translation_error_mujoco": m_mj.translation_error_pct,
    }


def _pct(value: float, reference: float) -> str:
    return f"{100.0 * (value / reference - 1.0):+.1f} %"


def physics_table() -> list[str]:
    """Markdown rows: each analytic case on both engines."""
    lines = [
        "| case | analytic | ours | mujoco |",
        "|---|---|---|---|",
    ]
    for label, heading in (("free slide, axis", 0.0), ("free slide, diagonal", 45.0)):
        a, b = (free_slide(e, heading) for e in ENGINES)
        lines.append(
            f"| {label}: distance [mm] (v0 = {SLIDE_SPEED} m/s, μ_g = {MU_GROUND}) "
            f"| {1e3 * a['expected']:.2f} | {1e3 * a['distance']:.2f} "
            f"({_pct(a['distance'], a['expected'])}) | {1e3 * b['distance']:.2f} "
            f"({_pct(b['distance'], b['expected'])}) |"
        )
    for omega0, dt in SPIN_CASES:
        a, b = (spin_down(e, omega0, dt) for e in ENGINES)
        lines.append(
            f"| spin-down from {omega0:g} rad/s (h = {dt:g} s): angle [deg] "
            f"| {math.degrees(a['expected']):.2f} "
            f"| {math.degrees(a['angle']):.2f} ({_pct(a['angle'], a['expected'])}) "
            f"| {math.degrees(b['angle']):.2f} ({_pct(b['angle'], b['expected'])}) |"
        )
    a, b = (rest(e) for e in ENGINES)
    lines.append(
        f"| rest 5 s: largest pose drift [µm or µrad]; sink [mm] | 0; 0 | {1e6 * a['drift']:.2g}; "
        f"0 | {1e6 * b['drift']:.2g}; {1e3 * b['sink']:.2f} |"
    )
    a, b = (straight_push(e) for e in ENGINES)
    for key, label in (("mean", "mean"), ("min", "min"), ("max", "max")):
        lines.append(
            f"| straight push, cruise Σλ_n {label} [N] | {a['expected']:.3f} "
            f"| {a[key]:.4f} ({_pct(a[key], a['expected'])}) "
            f"| {b[key]:.4f} ({_pct(b[key], b['expected'])}) |"
        )
    lines.append(
        f"| straight push: Σλ_n std over the cruise [mN] | 0 | {1e3 * a['std']:.2f} "
        f"| {1e3 * b['std']:.2f} |"
    )
    lines.append(
        f"| straight push: deepest prong penetration [mm] | < 1 | "
        f"{1e3 * a['penetration']:.3f} | {1e3 * b['penetration']:.3f} |"
    )
    lines.append(
        f"| straight push: distance pushed [mm] | {1e3 * (STRAIGHT_GOAL.x - 0.42):.1f} "
        f"| {1e3 * a['distance']:.2f} | {1e3 * b['distance']:.2f} |"
    )
    return lines


def arc_table() -> list[str]:
    """Markdown rows: one planned arc push per object and profile on both engines."""
    lines = [
        "| object | profile | pose diff RMS [mm, deg] | final [mm, deg] | mean abs Σλ_n "
        "diff [N] | force error ours / mujoco [N] | translation error ours / mujoco [%] "
        "| penetration ours / mujoco [mm] |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for obj in OBJECTS:
        for profile in PROFILES:
            r = arc_push(obj, profile)
            lines.append(
                f"| {obj} | {profile} | {1e3 * r['rms_position']:.2f}, "
                f"{math.degrees(r['rms_angle']):.2f} | {1e3 * r['final_position']:.2f}, "
                f"{math.degrees(r['final_angle']):.2f} | {r['force_difference']:.3f} "
                f"| {r['force_error_ours']:.3f} / {r['force_error_mujoco']:.3f} "
                f"| {r['translation_error_ours']:.2f} / {r['translation_error_mujoco']:.2f} "
                f"| {1e3 * r['penetration_ours']:.3f} / {1e3 * r['penetration_mujoco']:.3f} |"
            )
    return lines


def validation_markdown() -> str:
    """Both tables with the command that made them."""
    command = "python -m studies.mujoco_validation --docs docs/mujoco.md"
    parts = [
        BEGIN,
        f"Generated by `{command}` (h = 0.01 s, nominal parameters; about 15 s).",
        "",
        *physics_table(),
        "",
        f"Planned arc pushes to {ARC_GOAL.x - 0.42:.2f} m forward, {ARC_GOAL.y:.2f} m left, "
        f"{math.degrees(ARC_GOAL.theta):.0f}° (same plan, same PD, both engines):",
        "",
        *arc_table(),
        END,
    ]
    return "\n".join(parts) + "\n"


def replace_block(text: str, block: str, begin: str = BEGIN, end: str = END) -> str:
    """``text`` with its generated block (``begin`` … ``end``) replaced by ``block``;
    appended if the page has none."""
    if begin in text and end in text:
        head, rest_ = text.split(begin, 1)
        tail = rest_.split(end, 1)[1].lstrip("\n")
        return head + block + tail
    return text.rstrip("\n") + "\n\n" + block


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m studies.mujoco_validation", description=__doc__.splitlines()[0]
    )
    parser.add_argument("--docs", type=Path, help="page whose generated block to rewrite")
    args = parser.parse_args(argv)
    block = validation_markdown()
    sys.stdout.write(block)
    if args.docs is not None:
        text = args.docs.read_text(encoding="utf-8") if args.docs.exists() else ""
        page = replace_block(text, block)
        write_atomic(args.docs, lambda tmp: tmp.write_text(page, encoding="utf-8"))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
