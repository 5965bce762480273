"""``make bench``, engines side by side: our world and the MuJoCo world on the same scenes.

Part of :mod:`benchmarks.suite`. Four scenes, each built once per engine: the arm pushing
the cube at 1 cm/s (``world.step`` alone timed), the same push under the PD law with the law
timed too (the closed loop a controller runs), a closed-loop PD push step (``Episode.step``:
controller, reference, record and world), and the cube alone sliding. The first two also time MuJoCo
without pushctl's interface (``mj_step`` alone, and the PD law around it). The process is
pinned to one core while it runs, the engines alternate in blocks of :data:`BLOCK` steps (so
both see the same machine load), and each figure is the median of the single-step times; the
rows give both medians and their ratio ours / mujoco. Run alone:
``python -m benchmarks.engines``.
"""

from __future__ import annotations

import math
import os
import statistics
import time
from collections.abc import Callable
from contextlib import contextmanager
from typing import Any

import numpy as np

import pushctl
from pushctl.arm import ArmTerms
from pushctl.control import load_gains
from pushctl.control.pd import PDCommand, PDController
from pushctl.engines import ENGINES
from pushctl.episode import Episode, Scenario
from pushctl.types import PlanarPose

BLOCK = 50
"""Steps timed on one engine before switching to the other."""
GOAL = PlanarPose.from_degrees(0.62, 0.03, 30.0)


@contextmanager
def pinned_to_one_core():
    """Run the body on one CPU (the first this process may use), then restore the set."""
    if not hasattr(os, "sched_setaffinity"):  # not Linux: run unpinned
        yield
        return
    cores = os.sched_getaffinity(0)
    os.sched_setaffinity(0, {min(cores)})
    try:
        yield
    finally:
        os.sched_setaffinity(0, cores)


def _cube_at_the_prongs(engine: str):
    """A world of ``engine`` with the arm at its ready pose and the cube's face at the
    prongs: ``(world, arm, the pusher's placement)``."""
    world = pushctl.make_world("cube", engine=engine)
    arm = world.arm
    assert arm is not None
    start = arm.pusher_placement(arm.q_ready)
    world.reset(
        object_pose=(start.translation[0] + world.object.face_offset, start.translation[1], 0.0)
    )
    return world, arm, start


def pushing_world(engine: str, speed: float = 0.01, raw: bool = False):
    """A world whose pusher drives the cube forward at ``speed`` [m/s], prongs in contact,
    and its step: a plain operational-space velocity loop (q̇_des = J⁺ v_des, τ = g + K_v
    q̇_des, K_v implicit) whose own time is not counted. Returns ``step() -> seconds``.
    ``raw`` (MuJoCo only): time ``mujoco.mj_step`` alone, without the world's reading of
    forces, gaps and state (what the engine costs before our interface)."""
    world, arm, start = _cube_at_the_prongs(engine)
    kv, gain, clock = 20.0, 5.0, [0.0]

    def torque() -> np.ndarray:
        terms = world.arm_terms
        assert terms is not None
        target = start.translation + np.array([speed * clock[0], 0.0, 0.0])
        linear = [speed, 0.0, 0.0] + gain * (target - terms.pusher_position)
        twist = np.concatenate((linear, np.zeros(3)))
        q_dot = np.linalg.lstsq(terms.pusher_jacobian, twist, rcond=1e-4)[0]
        clock[0] += world.config.dt
        return terms.g + kv * q_dot

    def step() -> float:
        tau = torque()
        t0 = time.perf_counter()
        world.step(tau, implicit_kv=kv)
        return time.perf_counter() - t0

    def raw_step() -> float:
        tau = torque()
        mj = world.model, world.data  # type: ignore[union-attr]
        mj[0].dof_damping[:7] = kv
        mj[1].qfrc_applied[:7] = tau
        t0 = time.perf_counter()
        mj_step(*mj)
        seconds = time.perf_counter() - t0
        world._terms = None  # type: ignore[union-attr]  # the controller reads the new state
        return seconds

    for _ in range(100):  # into steady sliding contact
        step()
    if raw:
        from mujoco import mj_step

        return raw_step
    return step


def pd_pushing_world(engine: str, raw: bool = False) -> Callable[[], float]:
    """The closed loop: the PD law (:meth:`PDController.command`, compiled; shipped
    gains) servoing the pusher onto a target that moves at 1 cm/s, and the world step, both
    timed: ``step() -> seconds``. The controller reads the world's own arm terms. ``raw``
    (MuJoCo only): the loop a user would write around MuJoCo alone, the arm's terms from
    :meth:`ArmModel.compute` (Pinocchio through pushctl's library) at MuJoCo's state, the
    same PD law, then ``mujoco.mj_step``."""
    _, step = pd_push(engine, raw)
    for _ in range(100):  # into steady sliding contact
        step()
    return step


def pd_push(engine: str, raw: bool = False):
    """:func:`pd_pushing_world`'s world (reset, the cube against the prongs) and its step,
    not yet stepped: ``(world, step)``."""
    world, arm, start = _cube_at_the_prongs(engine)
    controller = PDController(arm, load_gains(), world.config.dt)
    yaw = math.atan2(start.rotation[1, 0], start.rotation[0, 0])
    twist_ff, clock = np.array([0.01, 0.0, 0.0, 0.0, 0.0, 0.0]), [0.0]

    def command(terms: ArmTerms, q: np.ndarray) -> PDCommand:
        target = start.translation + np.array([0.01 * clock[0], 0.0, 0.0])
        clock[0] += world.config.dt
        return controller.command(terms, q, target, yaw, twist_ff)

    def step() -> float:
        t0 = time.perf_counter()
        terms = world.arm_terms
        assert terms is not None
        pd = command(terms, world.q)
        world.step(pd.tau, implicit_kv=pd.implicit_kv)
        return time.perf_counter() - t0

    def raw_step() -> float:
        model, data = world.model, world.data  # type: ignore[union-attr]
        t0 = time.perf_counter()
        q = world.q  # MuJoCo's state, read from its data
        pd = command(arm.compute(q, world.v), q)
        model.dof_damping[: arm.nv] = pd.implicit_kv
        data.qfrc_applied[: arm.nv] = pd.tau
        mj_step(model, data)
        return time.perf_counter() - t0

    if raw:
        from mujoco import mj_step

        return world, raw_step
    return world, step


def closed_loop(engine: str) -> Callable[[], float]:
    """A PD push (cube, chirp, shipped gains); ``step() -> seconds`` of one ``Episode.step``,
    starting the push again when it ends."""
    episode = Episode(Scenario(object="cube", profile="chirp", goal=GOAL), gains=load_gains())
    episode = Episode(episode.scenario, gains=episode.gains, plan=episode.plan, engine=engine)
    episode.reset()

    def step() -> float:
        if episode.done:
            episode.reset()
        t0 = time.perf_counter()
        episode.step()
        return time.perf_counter() - t0

    return step


def object_alone(engine: str) -> Callable[[], float]:
    """The cube alone, sliding throughout (launched at 1 km/s); ``step() -> seconds``."""
    world = pushctl.make_world("cube", arm=None, engine=engine)
    world.reset(object_pose=(0.0, 0.0, 0.0), object_velocity=(1e3, 0.0, 0.1))

    def step() -> float:
        t0 = time.perf_counter()
        world.step()
        return time.perf_counter() - t0

    return step


def interleaved_medians(steppers: dict[str, Callable[[], float]], steps: int) -> dict[str, float]:
    """Median single-step time [µs] of each stepper, ``steps`` each, alternating in blocks."""
    times: dict[str, list[float]] = {name: [] for name in steppers}
    for step in steppers.values():  # warm-up (numba loads, caches fill)
        for _ in range(BLOCK):
            step()
    for _ in range(max(1, steps // BLOCK)):
        for name, step in steppers.items():
            times[name].extend(step() for _ in range(BLOCK))
    return {name: 1e6 * statistics.median(values) for name, values in times.items()}


SCENES: tuple[tuple[str, Callable[[str], Callable[[], float]], str], ...] = (
    ("world step arm+cube", pushing_world, "kinova pushing the cube at 1 cm/s, h = 0.01 s"),
    ("PD and world step", pd_pushing_world, "PD law + world step, the cube pushed at 1 cm/s"),
    ("closed-loop step", closed_loop, "PD push step (controller + world), cube chirp"),
    ("world step object only", object_alone, "cube sliding on the table"),
)

RAW_NOTES = {
    pushing_world: "MuJoCo's step without our interface (forces in our frames, gaps, state "
    "copies), interleaved with the rows above",
    pd_pushing_world: "the same PD law on the arm's terms at MuJoCo's state (Pinocchio), then "
    "MuJoCo's step without our interface: the same closed loop around MuJoCo",
}
"""The scenes that also time MuJoCo without pushctl's interface (``build(engine, raw=True)``),
and what their raw row holds."""


def engine_rows(steps: int = 2000) -> list[dict[str, Any]]:
    """Bench rows: per scene, each engine's median step [µs] and the ratio ours / mujoco."""
    rows: list[dict[str, Any]] = []
    with pinned_to_one_core():
        for label, build, note in SCENES:
            steppers = {e: build(e) for e in ENGINES}
            if build in RAW_NOTES:
                steppers["mj_step"] = build("mujoco", raw=True)  # type: ignore[call-arg]
            medians = interleaved_medians(steppers, steps)
            for engine in ENGINES:
                rows.append(
                    {
                        "name": f"{label} [{engine}]",
                        "value": medians[engine],
                        "unit": "us",
                        "note": f"{note}; one core, engines interleaved, median of {steps}",
                    }
                )
            rows.append(
                {
                    "name": f"{label} ours/mujoco",
                    "value": medians["ours"] / medians["mujoco"],
                    "unit": "1",
                    "note": "ratio of the two medians above (> 1: MuJoCo is faster)",
                }
            )
            if "mj_step" in medians:
                rows.append(
                    {
                        "name": f"{label} [mujoco mj_step alone]",
                        "value": medians["mj_step"],
                        "unit": "us",
                        "note": RAW_NOTES[build],
                    }
                )
                rows.append(
                    {
                        "name": f"{label} ours/mj_step alone",
                        "value": medians["ours"] / medians["mj_step"],
                        "unit": "1",
                        "note": "ratio of the two medians (> 1: MuJoCo alone is faster)",
                    }
                )
    return rows


def main() -> int:
    for row in engine_rows():
        print(f"{row['name']:<40} {row['value']:10.3f} {row['unit']:<3} {row['note']}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
