"""Joining or starting Ray, and pools of stateful workers.

A *session* (:func:`session`) connects this process to Ray once: to the cluster at
``address`` (or ``RAY_ADDRESS``), else to a local instance started on this machine's cores
with no dashboard and warnings only (on a 2-core laptop Ray's own processes should cost
little), whose workers run at the command's own priority (:data:`WORKER_NICENESS`). A
session opened inside another (a test's, a command's) reuses it and leaves it running.

A :class:`WorkerPool` is ``n`` Ray actors, each holding one object built from a factory
(an evaluation context, a training collector), so that per-process set-up (environments,
JIT-compiled kernels, the actor network) is paid once per worker, as with a process pool.
:func:`run_tasks` runs long calls (a training seed each) as Ray tasks that Ray retries
after their worker died, with their progress posted on a board the caller polls.

This module is pushctl's only importer of Ray.
"""

from __future__ import annotations

import os
import signal
import socket
import textwrap
import threading
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import Future
from contextlib import contextmanager
from itertools import cycle
from typing import Any

import ray

from pushctl.distributed import reaper
from pushctl.errors import ConfigError, PushctlError

ADDRESS_VARIABLE = "RAY_ADDRESS"
RETRIES = 3
"""Times a worker whose process died is restarted, and its calls rerun."""
CONNECT_TIMEOUT = 5.0
"""Seconds to wait for a cluster's head to accept a connection."""
LOCAL_OBJECT_STORE = 256 * 1024**2
"""Object-store bytes of a local instance: results here are episodes' transitions and trial
rows (kilobytes to a few MB), and Ray's default (30 % of the RAM) only reserves /dev/shm."""
WORKER_NICENESS = 0
"""How much lower than this process's priority a local instance's workers run (Ray's
``worker_niceness``, an increment to the niceness they inherit). Ray's default, 15, keeps a
cluster's driver responsive; here the workers do all of a command's work while the driver
waits, and at 15 a worker's 0.64 s of work took 18.3 s beside a normal-priority process
spinning on its core (28×; 2.1× at 0: ``python -m benchmarks.worker_priority``). At 0
they run at the priority of the command that started them: ``nice pushctl train`` still
runs it all niced (docs/ray.md, *Ray on a laptop*)."""
_watcher: Any = None
"""The watcher of the local Ray instance this process started (:mod:`.reaper`), if any."""
POLL = 0.5
"""Seconds between progress reports of :func:`run_tasks` to its caller."""
AHEAD = 4
"""Items per worker that :meth:`WorkerPool.ordered` lets run, or wait finished, beyond the
first result not yet yielded."""


def address_from(option: str | None) -> str | None:
    """The cluster to join: ``option`` (``--address``), else ``RAY_ADDRESS``, else None
    (start Ray on this machine)."""
    return option or os.environ.get(ADDRESS_VARIABLE) or None


@contextmanager
def session(address: str | None = None) -> Iterator[None]:
    """Ray connected for the block: reused if this process is already connected, else
    joined at ``address`` (see :func:`address_from`) or started locally, and shut down at
    the end. ConfigError (one line) if no cluster answers at the address."""
    if ray.is_initialized():
        yield
        return
    connect(address)
    try:
        yield
    finally:
        shutdown()


def shutdown() -> None:
    """Disconnect from Ray; a local instance this process started stops, and its watcher
    (:mod:`pushctl.distributed.reaper`) ends whatever of it is left."""
    global _watcher
    ray.shutdown()
    reaper.stop(_watcher)
    _watcher = None


def connect(
    address: str | None = None,
    num_cpus: int | None = None,
    worker_niceness: int = WORKER_NICENESS,
) -> None:
    """Connect this process to Ray (see :func:`session`); ``num_cpus`` of a local instance
    defaults to the machine's cores, ``worker_niceness`` is its workers' (Ray's
    ``worker_niceness``; a cluster joined at an address keeps its own)."""
    global _watcher
    os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
    # Ray's C++ log lines (a lost raylet's, one per task) would bury the command's own
    # one-line error under a screen of them; a fatal one still shows
    os.environ.setdefault("RAY_BACKEND_LOG_LEVEL", "fatal")
    quiet: dict[str, Any] = {"logging_level": "ERROR", "log_to_driver": False}
    target = address_from(address)
    with _own_sigterm_handler():
        if target is not None:
            _check_reachable(target)
            try:
                ray.init(address=target, **quiet)
            except (ConnectionError, RuntimeError, ValueError) as exc:
                reason = " ".join(str(exc).split())[:160]
                raise ConfigError(
                    f"--address {target}: no Ray cluster answers there ({reason}); start one "
                    "with `ray start --head` or leave out --address and RAY_ADDRESS to run "
                    "locally"
                ) from None
            return
        ray.init(
            num_cpus=num_cpus or os.cpu_count() or 1,
            include_dashboard=False,
            object_store_memory=LOCAL_OBJECT_STORE,
            _system_config={"worker_niceness": worker_niceness},
            **quiet,
        )
        _watcher = reaper.watch()


@contextmanager
def _own_sigterm_handler() -> Iterator[None]:
    """Keep this process's SIGTERM handler across ``ray.init``, which replaces it with one
    calling ``sys.exit(15)`` (the command's own handler stops it cleanly: Ray shut down,
    what was kept said)."""
    main = threading.current_thread() is threading.main_thread()
    before = signal.getsignal(signal.SIGTERM) if main else None
    try:
        yield
    finally:
        if main and before is not None:
            signal.signal(signal.SIGTERM, before)


def _check_reachable(address: str) -> None:
    """ConfigError (one line) if a ``host:port`` address does not accept a connection within
    :data:`CONNECT_TIMEOUT` s: ``ray.init`` would retry such an address for minutes.
    Other forms (``auto``, ``ray://…``) are left to Ray."""
    host, _, port = address.rpartition(":")
    if "://" in address or not host or not port.isdigit():
        return
    try:
        socket.create_connection((host, int(port)), timeout=CONNECT_TIMEOUT).close()
    except OSError as exc:
        raise ConfigError(
            f"--address {address}: no Ray cluster answers there ({exc.strerror or exc}); "
            "start one with `ray start --head` or leave out --address and RAY_ADDRESS "
            "to run locally"
        ) from None


def cluster_cpus() -> float:
    """CPUs of the connected cluster (1 if it reports none)."""
    return float(ray.cluster_resources().get("CPU", 1.0)) or 1.0


def cpus_per_worker(workers: int) -> float:
    """The CPU share each of ``workers`` actors asks for: one core each while the cluster
    has enough, else an equal share of it, so that every worker starts (a worker waiting for
    a core that never frees would hold its share of the work forever)."""
    return min(1.0, cluster_cpus() / max(1, workers))


@ray.remote(max_restarts=RETRIES, max_task_retries=RETRIES)
class _Host:
    """One worker process holding ``factory(*args)``; :meth:`call` runs one of its methods.
    A host whose process dies is restarted (``factory`` runs again) and the calls it had
    are run again: the pools' calls are pure functions of their arguments (an episode of
    a seed, an evaluation trial), so a retried call returns what the first would have."""

    def __init__(self, factory: Callable[..., Any], args: tuple[Any, ...]) -> None:
        self.held = factory(*args)

    def call(self, method: str, *args: Any) -> Any:
        return getattr(self.held, method)(*args)


@ray.remote(num_cpus=0)
class _Board:
    """Where running tasks post their progress and the driver reads it. It holds no core,
    and its process imports only this module (not torch)."""

    def __init__(self) -> None:
        self.status: dict[str, Any] = {}

    def post(self, key: str, status: Any) -> None:
        self.status[key] = status

    def read(self) -> dict[str, Any]:
        return self.status


def new_board() -> Any:
    """A progress board (an actor handle: ``board.post.remote(key, status)`` from tasks,
    ``ray.get(board.read.remote())`` from the driver). Call inside a :func:`session`."""
    board: Any = _Board
    return board.remote()


class WorkerPool:
    """``workers`` Ray actors, each holding ``factory(*args)``. Call inside a :func:`session`.

    :meth:`ordered` runs a method over many inputs, results in input order, each input
    sent to the first idle worker; :meth:`submit` sends one call to the next worker in turn
    and returns a :class:`concurrent.futures.Future`.
    """

    def __init__(self, workers: int, factory: Callable[..., Any], args: tuple[Any, ...]) -> None:
        share = cpus_per_worker(workers)
        host: Any = _Host  # a Ray actor class: .options and .remote come from the decorator
        self._actors = [host.options(num_cpus=share).remote(factory, args) for _ in range(workers)]
        self._turn = cycle(self._actors)

    def ordered(self, method: str, items: Iterable[Any], ahead: int = AHEAD) -> Iterator[Any]:
        """``getattr(held, method)(item)`` for each item, yielded in input order.

        A worker gets the next item as soon as it finishes one, even while an earlier item
        still runs elsewhere (Ray's ``ActorPool.map`` frees a worker only once its result is
        taken in order, so a fast worker waited for a slow one's job). At most ``ahead`` ×
        workers items run or wait finished beyond the first not yet yielded, which bounds the
        results held here."""
        todo = list(items)
        window = max(1, ahead) * len(self._actors)
        idle = list(self._actors)
        running: dict[Any, tuple[int, Any]] = {}  # ObjectRef → (item index, actor)
        finished: dict[int, Any] = {}  # item index → ObjectRef
        sent = yielded = 0
        while yielded < len(todo):
            while idle and sent < len(todo) and sent < yielded + window:
                actor = idle.pop()
                running[actor.call.remote(method, todo[sent])] = (sent, actor)
                sent += 1
            if yielded in finished:
                yield ray.get(finished.pop(yielded))
                yielded += 1
                continue
            ready, _ = ray.wait(list(running), num_returns=1)
            for ref in ready:
                index, actor = running.pop(ref)
                finished[index] = ref
                idle.append(actor)

    def submit(self, method: str, *args: Any) -> Future[Any]:
        return next(self._turn).call.remote(method, *args).future()

    def close(self) -> None:
        for actor in self._actors:
            ray.kill(actor)
        self._actors = []

    def __enter__(self) -> WorkerPool:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


Post = Callable[[str, Any], None]
"""A task's progress report: ``post(key, status)``, ``status`` plain data (a tuple)."""


@ray.remote(num_cpus=1, max_retries=RETRIES, retry_exceptions=False)
def _task(fn: Callable[..., Any], args: tuple[Any, ...], board: Any) -> Any:
    post: Post = lambda key, status: board.post.remote(key, status)  # noqa: E731
    return fn(*args, post)


def run_tasks(
    fn: Callable[..., Any],
    calls: list[tuple[str, tuple[Any, ...]]],
    cpus: float,
    on_progress: Callable[[dict[str, Any]], None] | None = None,
) -> list[Any]:
    """``fn(*args, post)`` for each ``(name, args)`` of ``calls``, each a Ray task asking
    for ``cpus`` and rerun from the start (up to :data:`RETRIES` times) if its worker
    dies, so ``fn`` must resume its own work; every :data:`POLL` s ``on_progress`` gets
    what the tasks last posted, by key. Call inside a :func:`session`. Results in the calls'
    order. A task that fails raises its error: a PushctlError keeps its one line, prefixed
    by the call's name; a task Ray gave up on becomes one line saying how to continue; any
    other error (a bug) is raised as it is. On any way out, unfinished tasks are cancelled."""
    board = new_board()
    task = _task.options(num_cpus=cpus)
    refs = {task.remote(fn, args, board): name for name, args in calls}
    waiting = list(refs)
    try:
        while waiting:
            ready, waiting = ray.wait(waiting, num_returns=len(waiting), timeout=POLL)
            for ref in ready:
                _raise_failure(ref, refs[ref])
            if on_progress is not None:
                on_progress(ray.get(board.read.remote()))
    finally:
        for ref in waiting:
            ray.cancel(ref, force=True)
    return [ray.get(ref) for ref in refs]


def _raise_failure(ref: Any, name: str) -> None:
    """Nothing if the task of ``ref`` succeeded; else its error, as :func:`run_tasks` says."""
    try:
        ray.get(ref)
    except ray.exceptions.RayTaskError as exc:
        cause = exc.cause
        if isinstance(cause, PushctlError):
            raise type(cause)(f"{name}: {cause}") from None
        raise
    except ray.exceptions.RayError as exc:
        reason = textwrap.shorten(str(exc), 160, placeholder=" …")  # whole words
        raise PushctlError(
            f"{name}: Ray gave up on its task ({type(exc).__name__}: {reason}); "
            "rerun with --resume to continue from its last checkpoint"
        ) from None
