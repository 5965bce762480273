"""The reaper ends the Ray processes of a command killed with ``SIGKILL``: a stand-in
command starts a process that runs from a ``ray`` directory (as Ray's agents do), is
killed, and the process must be gone within a few seconds; a process of the same command
that is not Ray's is spared."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

pytestmark = pytest.mark.skipif(not Path("/proc/self/stat").is_file(), reason="reads /proc")


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def test_a_killed_command_s_ray_processes_die_and_others_are_spared(tmp_path: Path) -> None:
    ray_dir = tmp_path / "ray"
    ray_dir.mkdir()
    sleeper = "import time\nwhile True: time.sleep(0.1)\n"
    (ray_dir / "agent.py").write_text(sleeper)
    (tmp_path / "other.py").write_text(sleeper)
    command = textwrap.dedent(
        f"""
        import subprocess, sys, time
        from pushctl.distributed import reaper
        watcher = reaper.watch()
        ray = subprocess.Popen([sys.executable, {str(ray_dir / "agent.py")!r}])
        other = subprocess.Popen([sys.executable, {str(tmp_path / "other.py")!r}])
        print(ray.pid, other.pid, flush=True)
        time.sleep(60)
        """
    )
    process = subprocess.Popen([sys.executable, "-c", command], stdout=subprocess.PIPE, text=True)
    ray_pid, other_pid = map(int, process.stdout.readline().split())
    try:
        time.sleep(1.5)  # the watcher notes descendants every 0.5 s
        os.kill(process.pid, signal.SIGKILL)
        process.wait()
        deadline = time.monotonic() + 10
        while _alive(ray_pid) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert not _alive(ray_pid)
        assert _alive(other_pid)
    finally:
        for pid in (ray_pid, other_pid):
            try:
                os.kill(pid, signal.SIGKILL)
            except OSError:
                pass
