"""What the fault tests share: the one-line refusal they expect, another process holding an
output's lock, and recorded pushes to replay."""

from __future__ import annotations

import contextlib
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path


def one_error_line(result, *fragments: str) -> str:
    """The single ``error:`` line of a refused command (exit code 2, no traceback), which
    holds every one of ``fragments``."""
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("error:"), result.stderr
    for fragment in fragments:
        assert fragment in lines[0], lines[0]
    return lines[0]


@contextlib.contextmanager
def lock_held_elsewhere(lock: Path) -> Iterator[None]:
    """Another process holds ``lock`` (as a running pushctl command would) until the block
    ends; it is then killed, and the system releases its lock."""
    holder = subprocess.Popen(
        [sys.executable, "-c",
         "import fcntl, os, time\n"
         f"fd = os.open({str(lock)!r}, os.O_RDWR | os.O_CREAT)\n"
         "fcntl.flock(fd, fcntl.LOCK_EX); os.write(fd, str(os.getpid()).encode())\n"
         "print('held', flush=True); time.sleep(60)"],
        stdout=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        assert holder.stdout is not None and holder.stdout.readline().strip() == "held"
        yield
    finally:
        holder.kill()
        holder.wait()


def recorded_pushes(root: Path, n: int) -> Path:
    """``n`` pushes of a 80 mm square in the recorded pushes' format (their recorded ends
    the starts: what is timed is the replay, not the score) and a friction fit for them."""
    import math

    import pandas as pd

    from pushctl.realdata.data import TIP_RADIUS

    (root / "mit").mkdir(parents=True)
    rows = []
    for i in range(n):
        x0, y0, th0 = 0.001 * (i % 7), 0.001 * (i % 5), 0.1 * (i % 9)
        start = (-(0.04 + TIP_RADIUS + 3e-4), 0.005 * (i % 11) - 0.025)
        end = (start[0] + 0.05, start[1])
        c, s = math.cos(th0), math.sin(th0)
        tip = [(x0 + c * p[0] - s * p[1], y0 + s * p[0] + c * p[1]) for p in (start, end)]
        rows.append({"push_id": f"p{i}", "surface": "felt", "shape": "square",
                     "speed_mm_s": 20, "x0": x0, "y0": y0, "theta0": th0,
                     "tip_x0": tip[0][0], "tip_y0": tip[0][1], "tip_x1": tip[1][0],
                     "tip_y1": tip[1][1], "x1": x0, "y1": y0, "theta1": th0})  # fmt: skip
    pd.DataFrame(rows).to_csv(root / "mit" / "pushes.csv", index=False)
    corners = [(0.04, -0.04), (0.04, 0.04), (-0.04, 0.04), (-0.04, -0.04)]
    shapes = [{"shape": "square", "vertex": k, "x": x, "y": y} for k, (x, y) in enumerate(corners)]
    pd.DataFrame(shapes).to_csv(root / "mit" / "shapes.csv", index=False)
    fit = root / "fit.toml"
    fit.write_text("[surface.felt]\nmu_contact = 0.25\nmu_ground = 0.3\nrim_weight = 0.0\n")
    return root
