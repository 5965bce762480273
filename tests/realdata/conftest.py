"""Data sets in the recorded pushes' format, written by the tests (so every code path runs
without the real data), and the real one when it is present."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from pushctl.realdata.data import TIP_RADIUS
from pushctl.realdata.replay import ReplaySettings, SurfaceParameters, replay_pushes

REAL_DATA = Path(
    os.environ.get(
        "PUSHCTL_REALDATA", Path(__file__).resolve().parents[2] / ".." / "shared" / "realdata"
    )
)
TRUTH = SurfaceParameters(mu_contact=0.3, mu_ground=0.3, rim_weight=0.0)
SHAPES = {
    "square": np.array([(0.04, -0.04), (0.04, 0.04), (-0.04, 0.04), (-0.04, -0.04)]),
    # the pose frame at the right angle's neighbour, as in the MIT triangles
    "tri": np.array([(0.045, -0.08), (0.045, 0.045), (-0.08, 0.045)]),
}


@pytest.fixture(scope="session")
def real_data() -> Path:
    if not (REAL_DATA / "mit" / "pushes.csv").is_file():
        pytest.skip(f"the recorded pushes are not at {REAL_DATA}")
    return REAL_DATA


@pytest.fixture(scope="session")
def synthetic_data(tmp_path_factory) -> Path:
    """Pushes of a square and an off-centroid-framed triangle on one surface at one speed,
    their ends simulated with :data:`TRUTH` plus 0.3 mm / 0.3° of noise; Zhou's columns
    are the recorded ends with more noise."""
    root = tmp_path_factory.mktemp("synthetic")
    (root / "mit").mkdir()
    rng = np.random.default_rng(7)
    rows = []
    for shape, face_x, sign, span in (("square", 0.04, -1, (-0.03, 0.03)),
                                      ("tri", 0.045, 1, (-0.06, 0.03))):  # fmt: skip
        for i in range(8):
            x0, y0, th0 = rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1), rng.uniform(-3, 3)
            y_local = rng.uniform(*span)
            start = np.array((sign * (face_x + TIP_RADIUS + 3e-4), y_local))
            heading = (math.pi if sign > 0 else 0.0) + rng.uniform(-0.3, 0.3)
            end = start + 0.05 * np.array((math.cos(heading), math.sin(heading)))
            c, s = math.cos(th0), math.sin(th0)
            world = [(x0 + c * p[0] - s * p[1], y0 + s * p[0] + c * p[1]) for p in (start, end)]
            rows.append({"push_id": f"{shape}-{i:02d}", "surface": "felt", "shape": shape,
                         "speed_mm_s": 20, "x0": x0, "y0": y0, "theta0": th0,
                         "tip_x0": world[0][0], "tip_y0": world[0][1],
                         "tip_x1": world[1][0], "tip_y1": world[1][1]})  # fmt: skip
    pushes = pd.DataFrame(rows)
    ends = replay_pushes(pushes, SHAPES, {"felt": TRUTH}, ReplaySettings())
    noisy = ends + rng.normal(0, [3e-4, 3e-4, 0.005], ends.shape)
    pushes[["x1", "y1", "theta1"]] = noisy
    zhou = noisy + rng.normal(0, [2e-3, 2e-3, 0.03], ends.shape)
    pushes[["zhou_poly4_x1", "zhou_poly4_y1", "zhou_poly4_theta1"]] = zhou
    pushes.to_csv(root / "mit" / "pushes.csv", index=False)
    shapes = [{"shape": name, "vertex": k, "x": x, "y": y}
              for name, v in SHAPES.items() for k, (x, y) in enumerate(v)]  # fmt: skip
    pd.DataFrame(shapes).to_csv(root / "mit" / "shapes.csv", index=False)
    _write_log(root / "two_finger_logs" / "rect_flat" / "rect_0_0_0")
    return root


def _write_log(folder: Path) -> None:
    """Two logs of two segments each: the pusher (two fingers) pushes the 50 x 35 mm
    rectangle 30 mm along x, is lifted, pushes again; one vision dropout per log."""
    folder.mkdir(parents=True)
    for k in range(2):
        lines, t = ["0,0,0,0,0,0,0,1"], 100.0
        x_obj = 0.0
        for segment in range(2):
            for i in range(40):
                px = -25.0 - 2.5 - 0.5 + x_obj + i * 1.0
                x_now = max(x_obj, px + 27.5) if i > 0 else x_obj
                dropout = i == 20 and segment == 0
                obj = "0,0,0" if dropout else f"{x_now:.4f},{5 + 0.01 * k:.4f},0.0"
                lines.append(f"{t:.3f},{obj},{px:.4f},5.0,0.0,{segment + 1}")
                t += 0.03
            x_obj = x_now
            t += 2.0
        (folder / f"log{k}.txt").write_text("\n".join(lines) + "\n")
