"""Tests of pushctl.report.plan_figure: the figure's structure, that it draws the plan's own
data (CoM path, prong contacts) and that it saves to PNG."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from pushctl.arm import ArmConfig, load_arm
from pushctl.config import PusherConfig
from pushctl.objects import make_object
from pushctl.planning import Plan, make_plan
from pushctl.report import plan_figure

# (object, goal (x [m], y [m], θ [rad]), profile, with the arm)
CASES = {
    "cube-constant-arm": ("cube", (0.62, 0.03, math.radians(30)), "constant", True),
    "wedge-chirp-arm": ("wedge", (0.62, 0.03, math.radians(30)), "chirp", True),
    "wedge-trapezoid": ("wedge", (0.60, -0.02, math.radians(-20)), "trapezoid", False),
    "cube-straight": ("cube", (0.6, 0.0, 0.0), "constant", False),
}
N_AXES = 5  # top view, θ with its ω twin, forces, torques


def _plan(name: str) -> Plan:
    obj_name, goal, profile, with_arm = CASES[name]
    obj = make_object(obj_name)
    arm = load_arm(ArmConfig(pusher=PusherConfig(mass=obj.pusher_mass))) if with_arm else None
    return make_plan(obj, goal, profile=profile, arm=arm, duration=4.0, dt=0.02)


@pytest.fixture(scope="module", params=sorted(CASES))
def plan(request: pytest.FixtureRequest) -> Plan:
    return _plan(request.param)


def _lines(ax: Axes, gid: str) -> list[Line2D]:
    return [line for line in ax.get_lines() if line.get_gid() == gid]


def _legend_texts(ax: Axes) -> list[str]:
    legend = ax.get_legend()
    assert legend is not None
    return [text.get_text() for text in legend.get_texts()]


def test_figure_structure(plan: Plan) -> None:
    fig = plan_figure(plan)
    assert isinstance(fig, Figure)
    assert len(fig.axes) == N_AXES
    title = fig.get_suptitle()
    assert plan.obj.name in title and plan.trajectory.profile in title
    assert "feasible" in title


def test_com_path_is_the_planned_pose(plan: Plan) -> None:
    top = plan_figure(plan).axes[0]
    (path,) = _lines(top, "com_path")
    xy = np.column_stack([path.get_xdata(), path.get_ydata()]) / 1e3  # drawn in mm
    np.testing.assert_allclose(xy, plan.trajectory.pose[:, :2], atol=1e-12)


def test_prongs_sit_on_the_pusher_path(plan: Plan) -> None:
    """The prongs drawn at the first and last instants straddle the planner's pusher frame."""
    outlines = 3
    top = plan_figure(plan, outlines=outlines).axes[0]
    k = len(plan.forces.prong_points)
    dots = [_lines(top, f"prong_{i + 1}") for i in range(k)]
    assert all(len(d) == outlines for d in dots)
    for instant, step in ((0, 0), (-1, -1)):
        points = np.array([[d[instant].get_xdata()[0], d[instant].get_ydata()[0]] for d in dots])
        np.testing.assert_allclose(
            points.mean(axis=0) / 1e3, plan.pusher_positions[step, :2], atol=1e-9
        )


def test_icr_legend() -> None:
    straight = plan_figure(_plan("cube-straight")).axes[0]
    assert any("no ICR" in text for text in _legend_texts(straight))
    turning = plan_figure(_plan("cube-constant-arm")).axes[0]
    assert any(text.startswith("ICR, R = ") for text in _legend_texts(turning))
    far = make_plan(make_object("cube"), (0.5, 0.005, math.radians(2)), duration=2.0, dt=0.02)
    assert any("off plot" in text for text in _legend_texts(plan_figure(far).axes[0]))


def test_infeasible_plan_is_captioned() -> None:
    plan = make_plan(make_object("cube"), (0.6, 0.1, 0.0), duration=2.0, dt=0.02)
    assert plan.problems
    fig = plan_figure(plan)
    assert "INFEASIBLE" in fig.get_suptitle()
    assert fig.get_supxlabel().startswith(plan.problems[0][:40])


def test_saves_png(tmp_path: Path) -> None:
    """One case only: drawing (constrained layout) is most of the time of these tests."""
    out = tmp_path / "plan.png"
    plan_figure(_plan("wedge-chirp-arm")).savefig(out, dpi=40)
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
