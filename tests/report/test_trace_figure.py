"""Tests of pushctl.report.trace_figure: the figure's structure, that it draws the trace's own
data (desired θ, the CoM paths, one force line per prong), that it saves to PNG and SVG, and
that it draws any number of prongs from 1 to 4."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from pushctl.control import PDGains
from pushctl.episode import Episode, Scenario, Trace
from pushctl.report import trace_figure
from pushctl.types import PlanarPose

N_AXES = 7  # top view, θ, errors with the angle-error twin, normal, tangential, torque


@pytest.fixture(scope="module")
def trace() -> Trace:
    scenario = Scenario(
        object="cube", profile="chirp", goal=PlanarPose.from_degrees(0.55, 0.02, 20), duration=2.0
    )
    gains = PDGains(kp=0, kv=100, kx_linear=50, kx_angular=50)
    return Episode(scenario, gains=gains).run()


@pytest.fixture(scope="module")
def figure(trace: Trace) -> Figure:
    return trace_figure(trace)


def _with_prongs(trace: Trace, k: int) -> Trace:
    """``trace`` with ``k`` prongs: the per-prong arrays sliced or tiled (the totals kept)."""

    def resize(values: np.ndarray) -> np.ndarray:
        reps = -(-k // values.shape[1])
        return np.concatenate([values] * reps, axis=1)[:, :k]

    return dataclasses.replace(
        trace,
        contact_forces=resize(trace.contact_forces),
        desired_forces=resize(trace.desired_forces),
        prong_gaps=resize(trace.prong_gaps),
    )


def _line(ax: Axes, label: str) -> Line2D:
    (line,) = [line for line in ax.get_lines() if line.get_label() == label]
    return line


def _gids(fig: Figure, prefix: str) -> list[str]:
    return sorted(
        str(line.get_gid())
        for ax in fig.axes
        for line in ax.get_lines()
        if str(line.get_gid()).startswith(prefix)
    )


def test_figure_structure(figure: Figure, trace: Trace) -> None:
    assert isinstance(figure, Figure)
    assert len(figure.axes) == N_AXES
    title = figure.get_suptitle()
    assert f"{trace.n_prongs} prongs" in title and "final error" in title
    assert trace_figure(trace, title="run 7").get_suptitle() == "run 7"


def test_desired_theta_is_the_trace_in_degrees(figure: Figure, trace: Trace) -> None:
    (theta_ax,) = [ax for ax in figure.axes if ax.get_ylabel() == "θ [deg]"]
    line = _line(theta_ax, "θ desired")
    np.testing.assert_allclose(line.get_xdata(), trace.t)
    np.testing.assert_allclose(line.get_ydata(), np.degrees(trace.desired_pose[:, 2]))
    actual = _line(theta_ax, "θ actual")
    np.testing.assert_allclose(actual.get_ydata(), np.degrees(trace.object_pose[:, 2]))


def test_com_paths_in_mm(figure: Figure, trace: Trace) -> None:
    top = figure.axes[0]
    for gid, pose in (("com_desired", trace.desired_pose), ("com_actual", trace.object_pose)):
        (line,) = [line for line in top.get_lines() if line.get_gid() == gid]
        xy = np.column_stack([line.get_xdata(), line.get_ydata()]) / 1e3
        np.testing.assert_allclose(xy, pose[:, :2], atol=1e-12)


def test_one_force_line_per_prong(figure: Figure, trace: Trace) -> None:
    k = trace.n_prongs
    for name in ("normal", "tangential"):
        for kind in ("actual", "desired"):
            expected = sorted(f"{name}_{kind}_{i + 1}" for i in range(k))
            assert _gids(figure, f"{name}_{kind}_") == expected
    (normal_ax,) = [ax for ax in figure.axes if ax.get_ylabel() == "normal force [N]"]
    for i in range(k):
        (line,) = [
            line for line in normal_ax.get_lines() if line.get_gid() == f"normal_desired_{i + 1}"
        ]
        np.testing.assert_allclose(line.get_xdata(), trace.t[1:])  # row 0 skipped
        np.testing.assert_allclose(line.get_ydata(), trace.desired_forces[1:, i, 0])


@pytest.mark.parametrize("suffix", ["png", "svg"])
def test_saves(tmp_path: Path, figure: Figure, suffix: str) -> None:
    out = tmp_path / f"trace.{suffix}"
    figure.savefig(out, dpi=40)
    data = out.read_bytes()
    assert data
    if suffix == "png":
        assert data[:8] == b"\x89PNG\r\n\x1a\n"
    else:
        assert b"<svg" in data[:2000]


@pytest.mark.parametrize("k", [1, 3, 4])
def test_any_number_of_prongs(tmp_path: Path, trace: Trace, k: int) -> None:
    synthetic = _with_prongs(trace, k)
    assert synthetic.n_prongs == k
    fig = trace_figure(synthetic)
    assert len(fig.axes) == N_AXES
    assert len(_gids(fig, "normal_actual_")) == k
    assert len(_gids(fig, "tangential_desired_")) == k
    assert f"{k} prong" in fig.get_suptitle()
    fig.savefig(tmp_path / f"trace_{k}.png", dpi=40)


def test_transient_is_clipped_and_named(trace: Trace) -> None:
    """A large impact spike in the actual torque is clipped and named in the legend."""
    torque = trace.contact_torque.copy()
    torque[1] = 100.0 * np.abs(trace.desired_torque).max()
    fig = trace_figure(dataclasses.replace(trace, contact_torque=torque))
    (torque_ax,) = [ax for ax in fig.axes if ax.get_ylabel() == "torque τ_z [N·m]"]
    assert torque_ax.get_ylim()[1] < torque[1]
    legend = torque_ax.get_legend()
    assert legend is not None
    assert any(text.get_text().startswith("off scale") for text in legend.get_texts())
