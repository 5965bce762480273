"""The Ray processes of a killed command die with it.

A local Ray instance's head processes (GCS, raylet, monitors) receive ``SIGKILL`` when the
process that started them dies (Ray starts them with the kernel's parent-death signal), but
the raylet's own children (the dashboard and runtime-env agents, idle workers) do not: after
a ``kill -9`` of ``pushctl train`` they were alive half a minute later. :func:`watch` starts
this file as a small separate process (the standard library only, no package imports) that
notes the Ray processes the command started, and theirs, every :data:`INTERVAL` s and, once
the command is gone (its end of a pipe closes: on a normal exit after ``ray.shutdown()``, or
when it is killed), ends the noted ones still running: ``SIGTERM``, then ``SIGKILL`` after
:data:`GRACE` s.

Linux only (it reads ``/proc``); elsewhere :func:`watch` does nothing.
"""

from __future__ import annotations

import io
import os
import select
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import cast

INTERVAL = 0.5
"""Seconds between two notes of the command's descendants."""
GRACE = 0.5
"""Seconds a noted process has to end after ``SIGTERM`` before it is sent ``SIGKILL``."""


_BOOTSTRAP = (
    "import sys; path = sys.argv[1]; "
    "exec(compile(open(path).read(), path, 'exec')); _main(int(sys.argv[2]))"
)
"""Run this file's code in a bare interpreter and watch the pid given after it (the package's
one command line is Typer's, so this file has no ``__main__`` block of its own)."""


def watch() -> subprocess.Popen | None:
    """Start the watcher of this process; keep the returned handle for the process's life
    (its pipe is what the watcher waits on) and :func:`stop` it after ``ray.shutdown()``."""
    if not Path("/proc/self/stat").is_file():
        return None
    return subprocess.Popen(
        [sys.executable, "-I", "-S", "-c", _BOOTSTRAP, __file__, str(os.getpid())],
        stdin=subprocess.PIPE,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,  # a Ctrl-C or SIGTERM to the command's group spares it
    )


def stop(watcher: subprocess.Popen | None) -> None:
    """Close the watcher's pipe: it ends the command's leftover processes and exits."""
    if watcher is not None and watcher.stdin is not None:
        watcher.stdin.close()


def _stat(pid: int) -> tuple[int, int] | None:
    """(parent pid, start time in clock ticks) of ``pid``, or None if it is gone."""
    try:
        text = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    fields = text[text.rindex(")") + 2 :].split()
    return int(fields[1]), int(fields[19])


def _cmdline(pid: int) -> bytes:
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes()
    except OSError:
        return b""


def _ray_processes(command: int) -> set[tuple[int, int]]:
    """(pid, start time) of the Ray processes ``command`` started (its children run from
    Ray's package: GCS, raylet, monitors) and all of theirs (agents, workers); a child
    process of the command that runs a Ray instance of its own is not one of them."""
    children: dict[int, list[tuple[int, int]]] = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            stat = _stat(int(entry))
            if stat is not None:
                children.setdefault(stat[0], []).append((int(entry), stat[1]))
    roots = [child for child in children.get(command, []) if b"/ray/" in _cmdline(child[0])]
    found: set[tuple[int, int]] = set(roots)
    todo = [pid for pid, _ in roots]
    while todo:
        for child in children.get(todo.pop(), []):
            if child not in found:
                found.add(child)
                todo.append(child[0])
    return found


def _alive(noted: set[tuple[int, int]]) -> set[tuple[int, int]]:
    return {(pid, start) for pid, start in noted if (_stat(pid) or (0, -1))[1] == start}


def _end(noted: set[tuple[int, int]]) -> None:
    for sig in (signal.SIGTERM, signal.SIGKILL):
        for pid, _ in _alive(noted):
            try:
                os.kill(pid, sig)
            except OSError:
                pass
        deadline = time.monotonic() + GRACE
        while _alive(noted) and time.monotonic() < deadline:
            time.sleep(0.05)


def _main(command: int) -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    noted: set[tuple[int, int]] = set()
    me = os.getpid()
    # stdin is the command's pipe, which Python opens as a BufferedReader (typeshed says
    # only BinaryIO): read1 returns what the pipe holds without waiting for more
    pipe = cast(io.BufferedReader, sys.stdin.buffer)
    while True:
        noted |= {child for child in _ray_processes(command) if child[0] != me}
        readable, _, _ = select.select([sys.stdin], [], [], INTERVAL)
        if readable and not pipe.read1(1024):
            break  # the command closed the pipe or died
    _end(_alive(noted))
