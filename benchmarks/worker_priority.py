"""What a Ray worker's niceness costs when the machine is shared (docs/ray.md).

Run as ``python -m benchmarks.worker_priority [--work 0.5] [--repeats 3]``. For each
worker niceness (Ray's default 15, and :data:`~pushctl.distributed.engine.WORKER_NICENESS`),
a local Ray instance is started with it and one worker runs a fixed piece of pure-Python
arithmetic (about ``--work`` s on its own) pinned to one core: alone, then beside a
normal-priority process spinning on the same core, alternately, ``--repeats`` times. Prints
each case's median wall time and the slowdown beside the spinning process (2 would be a fair
half of the core).
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time

import ray

from pushctl.distributed.engine import WORKER_NICENESS, connect

SPIN = "import os; os.sched_setaffinity(0, {%d})\nwhile True: pass"
"""A normal-priority process that wants all of core %d."""


def _arithmetic(loops: int) -> float:
    """Wall time [s] of ``loops`` iterations of pure-Python arithmetic."""
    start, total = time.perf_counter(), 0
    for i in range(loops):
        total += i * i % 7
    return time.perf_counter() - start


@ray.remote(num_cpus=1)
def _timed_work(loops: int, core: int) -> tuple[float, int]:
    """:func:`_arithmetic` in a worker pinned to ``core``, and the worker's niceness."""
    os.sched_setaffinity(0, {core})
    return _arithmetic(loops), os.nice(0)


def _loops_for(seconds: float) -> int:
    """Iterations that take about ``seconds`` now (measured in this process)."""
    return max(1, int(200_000 * seconds / _arithmetic(200_000)))


def slowdowns(nicenesses: list[int], work: float, repeats: int) -> list[dict[str, float]]:
    """Per worker niceness: the worker's niceness, its median time alone and beside the
    spinning process [s], and their ratio. Starts and stops its own Ray instances."""
    if ray.is_initialized():
        raise RuntimeError("run on its own: it starts Ray with each niceness itself")
    core = min(os.sched_getaffinity(0))
    loops = _loops_for(work)
    rows = []
    for niceness in nicenesses:
        connect(num_cpus=1, worker_niceness=niceness)  # the local instance pushctl starts
        try:
            _, worker_nice = ray.get(_timed_work.remote(1000, core))  # the worker starts
            alone, shared = [], []
            for _ in range(repeats):
                alone.append(ray.get(_timed_work.remote(loops, core))[0])
                spinner = subprocess.Popen([sys.executable, "-c", SPIN % core])
                try:
                    time.sleep(0.2)  # let it start spinning
                    shared.append(ray.get(_timed_work.remote(loops, core))[0])
                finally:
                    spinner.kill()
                    spinner.wait()
        finally:
            ray.shutdown()
        median_alone, median_shared = statistics.median(alone), statistics.median(shared)
        rows.append(
            {
                "ray_worker_niceness": niceness,
                "worker_nice": worker_nice,
                "alone_s": median_alone,
                "beside_spinner_s": median_shared,
                "slowdown": median_shared / median_alone,
            }
        )
    return rows


def main(argv: list[str] | None = None) -> int:
    doc = __doc__.split("\n\n")[0]
    parser = argparse.ArgumentParser(prog="python -m benchmarks.worker_priority", description=doc)
    parser.add_argument("--work", type=float, default=0.5, help="seconds of work alone")
    parser.add_argument("--repeats", type=int, default=3, help="alternations per niceness")
    args = parser.parse_args(argv)
    if not (0.01 <= args.work <= 60.0) or not (1 <= args.repeats <= 50):
        message = "--work must be in 0.01..60 s and --repeats in 1..50"
        print(f"worker_priority: {message}, got {args.work} and {args.repeats}", file=sys.stderr)
        return 2
    for row in slowdowns([15, WORKER_NICENESS], args.work, args.repeats):
        print(
            f"worker_niceness {row['ray_worker_niceness']:>2} (worker at nice "
            f"{row['worker_nice']}): alone {row['alone_s']:.2f} s, beside a normal-priority "
            f"process on its core {row['beside_spinner_s']:.2f} s: {row['slowdown']:.1f}x"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
