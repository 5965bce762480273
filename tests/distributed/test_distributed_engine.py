"""The worker pool: results in input order, a worker killed with SIGKILL restarted and the
calls sent to it run again, the CPU share of more workers than cores, and the workers'
priority."""

from __future__ import annotations

import importlib
import os
import signal
from pathlib import Path

from pushctl.distributed.engine import WorkerPool, cpus_per_worker


def test_results_come_in_input_order(ray_local: None) -> None:
    # The held object is a stdlib one, so the workers need no test module to unpickle it.
    with WorkerPool(2, bytearray, (b"abcb",)) as pool:
        needles = [b"a", b"b", b"z", b"bc"] * 5
        assert list(pool.ordered("count", needles)) == [1, 2, 0, 1] * 5


def test_a_free_worker_takes_later_items_while_an_earlier_one_runs(
    ray_local: None, tmp_path: Path
) -> None:
    # Item 0 waits (at most 20 s) for a file that only item 3 makes: a worker that finished
    # item 1 must go on to items 2 and 3 before item 0's result is taken. With Ray's
    # ActorPool.map it waited for item 0, and item 0 gave up (exit status 1).
    flag = tmp_path / "flag"
    wait = f"for i in $(seq 400); do [ -e {flag} ] && exit 0; sleep 0.05; done; exit 1"
    items = [["sh", "-c", wait], ["true"], ["true"], ["touch", str(flag)], ["true"]]
    with WorkerPool(2, importlib.import_module, ("subprocess",)) as pool:
        done = list(pool.ordered("run", items, ahead=2))
    assert [run.args for run in done] == items  # in input order
    assert [run.returncode for run in done] == [0] * len(items)


def test_a_killed_worker_is_restarted_and_its_calls_rerun(ray_local: None) -> None:
    # Each worker holds its own process id (the factory runs in the worker).
    with WorkerPool(1, os.getpid, ()) as pool:
        first = pool.submit("__int__").result()
        assert first != os.getpid()
        os.kill(first, signal.SIGKILL)
        calls = [pool.submit("__int__") for _ in range(3)]  # sent to the dead worker
        answers = {call.result(timeout=60) for call in calls}
        assert len(answers) == 1 and first not in answers  # a new process answered them all


def test_more_workers_than_cores_share_them(ray_local: None) -> None:
    assert cpus_per_worker(1) == 1.0
    assert cpus_per_worker(8) == 0.25  # the test instance has 2 CPUs


def test_local_workers_run_at_the_priority_of_the_command(ray_local: None) -> None:
    # Ray's default would renice them by 15 (a command at 0 gets workers at 15), so that any
    # process of normal priority took nearly all of a core they shared.
    with WorkerPool(2, importlib.import_module, ("os",)) as pool:
        assert list(pool.ordered("nice", [0, 0])) == [os.nice(0)] * 2
