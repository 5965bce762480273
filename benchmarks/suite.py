"""``make bench``: timings of the simulator core beside MuJoCo's, printed as a table, written
as CSV and as the table of ``docs/performance.md``.

Run from the checkout's root as ``python -m benchmarks.suite [--out results/bench.csv]
[--page docs/performance.md] [--profile] [--force]`` (an existing --out file is overwritten
only with ``--force``; ``make bench`` passes it; the page's generated block is rewritten only
when ``--page`` is given). Each figure is the median over many calls of one operation on one
core (this is a single-threaded process), in µs (plans: seconds); the CSV records how it was
made (command, version, git commit, date, machine). The two engines side by side come from
:mod:`benchmarks.engines`, the closed-loop rows from :mod:`benchmarks.episode`, the learning
rows from :mod:`benchmarks.rl`.
"""

from __future__ import annotations

import argparse
import cProfile
import io
import os
import platform
import pstats
import statistics
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from rich.console import Console
from rich.table import Table

import pushctl
from benchmarks.engines import engine_rows
from benchmarks.episode import episode_rows, profile_episode
from benchmarks.performance_page import bench_block, replace_block
from benchmarks.rl import rl_rows
from pushctl import native
from pushctl.contact.world import World
from pushctl.errors import ConfigError
from pushctl.files.output_guard import refuse_existing_files
from pushctl.files.provenance import provenance_line, recorded_argv, write_atomic, write_csv


def _median_us(func, repeats: int) -> float:
    """Median wall time of ``func()`` over ``repeats`` calls [µs], after a short warm-up."""
    for _ in range(min(50, max(1, repeats // 5))):
        func()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        func()
        times.append(time.perf_counter() - start)
    return 1e6 * statistics.median(times)


def _pushing_world(object_name: str = "cube", speed: float = 0.01):
    """A world whose pusher drives the object forward at ``speed`` [m/s], prongs in contact.

    The controller (not timed) is a plain operational-space velocity loop: the pusher frame
    follows a target moving at ``speed`` along +x, q̇_des = J⁺ v_des, and the joint torque is
    g(q) + K_v q̇_des with K_v applied implicitly by the world. Only ``World.step`` is timed.
    """
    world = pushctl.make_world(object=object_name)
    arm = world.arm
    assert arm is not None
    start = arm.pusher_placement(arm.q_ready)
    world.reset(
        object_pose=(start.translation[0] + world.object.face_offset, start.translation[1], 0.0)
    )
    kv, gain, clock = 20.0, 5.0, [0.0]

    def torque() -> np.ndarray:
        pose = arm.pusher_placement(world.q)
        target = start.translation + np.array([speed * clock[0], 0.0, 0.0])
        skew = start.rotation @ pose.rotation.T
        rotation_error = 0.5 * np.array(
            [skew[2, 1] - skew[1, 2], skew[0, 2] - skew[2, 0], skew[1, 0] - skew[0, 1]]
        )
        twist = np.concatenate(
            ([speed, 0.0, 0.0] + gain * (target - pose.translation), gain * rotation_error)
        )
        q_dot = np.linalg.lstsq(arm.pusher_jacobian(world.q), twist, rcond=1e-4)[0]
        clock[0] += world.config.dt
        return world.gravity_torque() + kv * q_dot

    for _ in range(100):  # into steady sliding contact
        world.step(torque(), implicit_kv=kv)
    return world, torque, kv


def _time_world_step(world: World, torque, kv: float, steps: int) -> tuple[float, int]:
    """Median µs of ``world.step`` alone, and how many steps had both prongs in contact."""
    times, in_contact = [], 0
    for _ in range(steps):
        tau = torque()
        start = time.perf_counter()
        result = world.step(tau, implicit_kv=kv)
        times.append(time.perf_counter() - start)
        in_contact += int(np.all(result.contact_forces[:, 0] > 0))
    return 1e6 * statistics.median(times), in_contact


def free_arm_energy(speed: float, steps: int = 2000, seed: int = 3) -> tuple[float, float]:
    """A free Kinova arm (no gravity, damping or torque) started at ``speed`` × N(0, 1) rad/s
    per joint: (kinetic energy kept, energy the ledger removed) after ``steps`` steps, both
    as fractions of the initial kinetic energy. What it removed is what semi-implicit Euler
    with explicit Coriolis terms would have created."""
    world = pushctl.make_world(gravity=0.0, damping=[0.0] * 7)
    arm = world.arm
    assert arm is not None
    world.reset(
        object_pose=(3.0, 3.0, 0.0), arm_v=speed * np.random.default_rng(seed).normal(size=7)
    )
    energy0 = arm.kinetic_energy(world.q, world.v)
    for _ in range(steps):
        world.step(np.zeros(7))
    return arm.kinetic_energy(world.q, world.v) / energy0, world.stats.energy_removed / energy0


def run_benchmarks(repeats: int = 2000) -> list[dict[str, Any]]:
    """All benchmark rows: name, value, unit, note."""
    rows: list[dict[str, Any]] = []
    world, torque, kv = _pushing_world("cube")
    problem = world.contact_problem(torque(), implicit_kv=kv)
    args = (problem.D, problem.b, problem.lo, problem.hi, problem.findex, problem.mu)
    solution = pushctl.solve_box_mlcp(*args)
    n = len(problem.b)
    note = f"cube contact set, 2 prongs + 4 supports, n = {n} rows"
    rows.append(
        {
            "name": "solve_box_mlcp cold",
            "value": _median_us(lambda: pushctl.solve_box_mlcp(*args), repeats),
            "unit": "us",
            "note": note + " (ProxQP fixed point + exact active-set finish)",
        }
    )
    rows.append(
        {
            "name": "solve_box_mlcp warm",
            "value": _median_us(
                lambda: pushctl.solve_box_mlcp(*args, warm_start=solution.p), repeats
            ),
            "unit": "us",
            "note": note + " (warm start from the previous solution, as in the world step)",
        }
    )
    step_us, in_contact = _time_world_step(world, torque, kv, repeats)
    rows.append(
        {
            "name": "world step arm+cube",
            "value": step_us,
            "unit": "us",
            "note": f"kinova-gen2-7dof pushing the cube at 1 cm/s, h = 0.01 s; both prongs "
            f"in contact in {in_contact}/{repeats} steps",
        }
    )
    rows.append(
        {"name": "steps per second arm+cube", "value": 1e6 / step_us, "unit": "1/s", "note": ""}
    )
    free = pushctl.make_world(object="cube", arm=None)
    free.reset(object_pose=(0.0, 0.0, 0.0), object_velocity=(1e3, 0.0, 0.1))  # slides throughout
    rows.append(
        {
            "name": "world step object only",
            "value": _median_us(free.step, repeats),
            "unit": "us",
            "note": "cube sliding on the table, 4 support points",
        }
    )
    rows.append(
        {
            "name": "steps per second object only",
            "value": 1e6 / rows[-1]["value"],
            "unit": "1/s",
            "note": "",
        }
    )
    for speed in (0.3, 1.0):
        kept, removed = free_arm_energy(speed)
        note = f"free Kinova arm, ~{speed} rad/s per joint, 20 s, no gravity or damping"
        rows.append(
            {"name": f"energy kept {speed} rad/s", "value": kept, "unit": "1", "note": note}
        )
        rows.append(
            {"name": f"energy removed {speed} rad/s", "value": removed, "unit": "1", "note": note}
        )
    rows.append(
        {
            "name": "mlcp fallbacks in timed steps",
            "value": world.stats.fallbacks,
            "unit": "count",
            "note": f"of {world.stats.solves} solves; warm-start hits {world.stats.warm_starts}",
        }
    )
    rows.extend(plan_rows())
    rows.extend(episode_rows())
    rows.extend(engine_rows())  # ours and MuJoCo side by side
    rows.extend(rl_rows())
    return rows


def profile_world_step(steps: int = 2000, top: int = 15) -> str:
    """cProfile of ``steps`` world steps of the pushing benchmark: where the time goes."""
    world, torque, kv = _pushing_world("cube")
    profiler = cProfile.Profile()
    for _ in range(steps):
        tau = torque()
        profiler.enable()
        world.step(tau, implicit_kv=kv)
        profiler.disable()
    out = io.StringIO()
    pstats.Stats(profiler, stream=out).sort_stats("tottime").print_stats(top)
    return out.getvalue()


def _machine() -> str:
    return f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, one used"


def _provenance(date: str) -> str:
    command = " ".join(["python -m benchmarks.suite", *recorded_argv(sys.argv[1:])])
    return provenance_line(command, f"{date}; {_machine()}; arm terms: {native.status()}")


def plan_rows(repeats: int = 7) -> list[dict[str, Any]]:
    """Wall time of a 2000-step plan with its force distribution, without and with the
    arm's reach check [s], median of ``repeats`` (the arm is loaded once, outside)."""
    from pushctl.arm import ArmConfig, load_arm
    from pushctl.config import PusherConfig
    from pushctl.objects import make_object
    from pushctl.planning import make_plan

    rows = []
    goal = (0.62, 0.03, np.radians(30.0))
    for name in ("cube", "wedge"):
        obj = make_object(name)
        arm = load_arm(ArmConfig(pusher=PusherConfig(mass=obj.pusher_mass)))
        for label, with_arm in (("forces", None), ("forces + reach", arm)):
            seconds = _median_us(
                lambda obj=obj, with_arm=with_arm: make_plan(
                    obj, goal, profile="chirp", arm=with_arm
                ),
                repeats,
            )
            rows.append(
                {
                    "name": f"plan {name} 2000 steps, {label}",
                    "value": 1e-6 * seconds,
                    "unit": "s",
                    "note": "chirp to (0.62, 0.03, 30 deg); ICR arc, ProxQP force distribution "
                    "with the offset search"
                    + (", IK at 51 points along the path" if with_arm else ""),
                }
            )
    return rows


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m benchmarks.suite", description=__doc__.splitlines()[0]
    )
    parser.add_argument("--out", type=Path, default=Path("results/bench.csv"))
    parser.add_argument(
        "--page", type=Path, default=None, help="rewrite this page's generated table"
    )
    parser.add_argument("--repeats", type=int, default=2000)
    parser.add_argument(
        "--profile",
        action="store_true",
        help="also print a cProfile of the world step and of a PD episode's push",
    )
    parser.add_argument("--force", action="store_true", help="overwrite an existing --out file")
    args = parser.parse_args(argv)
    try:
        refuse_existing_files("--out", (args.out,), args.force)
        if args.page is not None and not args.page.is_file():
            raise ConfigError(f"--page {args.page} is not a file; give docs/performance.md")
    except ConfigError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    rows = run_benchmarks(args.repeats)
    table = Table(title="pushctl core benchmarks (median, one core)")
    for column in ("name", "value", "unit", "note"):
        table.add_column(column)
    for row in rows:
        value = row["value"]
        table.add_row(
            row["name"], f"{value:.3f}" if value < 10 else f"{value:.1f}", row["unit"], row["note"]
        )
    Console().print(table)
    if args.profile:
        print(profile_world_step(args.repeats))
        print("PD episode, 2000-step push (cube, chirp):")
        print(profile_episode())
    date = time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())
    args.out.parent.mkdir(parents=True, exist_ok=True)
    write_csv(args.out, pd.DataFrame(rows), _provenance(date), float_format="%.4g")
    if args.page is not None:
        block = bench_block(rows, _machine(), date[:10])
        page = replace_block(args.page.read_text(encoding="utf-8"), block)
        write_atomic(args.page, lambda tmp: tmp.write_text(page, encoding="utf-8"))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
