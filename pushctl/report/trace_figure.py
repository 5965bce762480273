"""One-figure summary of a simulated push (a :class:`~pushctl.episode.Trace`), the paper's
Fig. 6 for one run.

Top row: a top view in millimetres (world frame) of the desired and actual centre-of-mass
paths with start and goal, and the pusher frame's planned and actual paths drawn faintly;
θ(t) [deg] desired and actual; the position error ‖p − p_des‖ [mm] with the angle error
θ − θ_des [deg] on a twin axis. Bottom row, sharing the time axis [s]: per-prong normal and
tangential forces [N], actual solid and desired dashed in the prong's colour (the
tangential panel with the friction cone ±μ_c λ_n,i dotted), and the total torque τ_z about
the centre of mass [N·m], actual and desired.

Pose panels draw every row t = 0 … T (row 0 is the start of the push, zero error). Force and
torque panels draw rows 1 … N only, the N steps of the push, as the metrics do: row 0 holds
the approach's last step, whose prongs are only just touching, and would add a spurious drop
to zero at t = 0.

The figure is a bare :class:`matplotlib.figure.Figure` (no pyplot, no global state): save
it with ``fig.savefig(path)``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from pushctl.report.plan_figure import (
    FONT,
    MM,
    RATE_COLOUR,
    prong_colour,
    prong_line_width,
)

if TYPE_CHECKING:
    from pushctl.episode import Trace

DESIRED_COLOUR = "0.45"
"""Colour of desired (planned) quantities that are not per prong."""
ACTUAL_COLOUR = "k"
"""Colour of actual (simulated) quantities that are not per prong."""
PUSHER_COLOUR = "#1f77b4"
"""Colour of the (faint) pusher paths in the top view."""
CLIP_SPAN = 3.0
"""A transient that stretches a time panel's y span more than this many fold is clipped."""
_FORCE_NAMES = {0: ("normal", "n"), 1: ("tangential", "t")}


def _style_handles() -> list[Line2D]:
    """Legend entries for the line styles: actual solid, desired dashed."""
    return [
        Line2D([], [], color="0.2", lw=1.6, label="actual"),
        Line2D([], [], color="0.2", lw=1.6, ls="--", label="desired"),
    ]


def _path_panel(ax: Axes, trace: Trace) -> None:
    """Top view [mm], equal aspect: CoM paths (gids ``"com_desired"``, ``"com_actual"``),
    start, goal and the actual end, and the pusher frame's paths faintly."""
    des, act = trace.desired_pose[:, :2] * MM, trace.object_pose[:, :2] * MM
    pusher, pusher_des = trace.pusher_position[:, :2] * MM, trace.pusher_position_des[:, :2] * MM
    ax.plot(*pusher.T, color=PUSHER_COLOUR, lw=1.2, alpha=0.5, label="pusher", zorder=1)
    ax.plot(*pusher_des.T, color=PUSHER_COLOUR, lw=1.2, ls="--", alpha=0.5, zorder=1)
    (line,) = ax.plot(*act.T, color=ACTUAL_COLOUR, lw=2.0, label="CoM actual", zorder=3)
    line.set_gid("com_actual")
    (line,) = ax.plot(*des.T, color=DESIRED_COLOUR, lw=1.6, ls="--", label="CoM desired", zorder=4)
    line.set_gid("com_desired")
    ax.plot(*des[0], "o", ms=7, mfc="white", mec="k", label="start", zorder=5)
    ax.plot(*des[-1], "*", ms=13, color="#e6a100", mec="k", label="goal", zorder=5)
    ax.plot(*act[-1], "X", ms=8, color=ACTUAL_COLOUR, mec="white", label="end", zorder=6)
    ax.set_aspect("equal", adjustable="datalim")
    ax.margins(0.08)
    ax.autoscale_view()
    handles, _ = ax.get_legend_handles_labels()
    ax.legend(handles=handles + _style_handles(), fontsize=FONT["legend"], loc="best", ncol=2)
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    ax.set_title("top view (pusher frame faint)", fontsize=FONT["label"])


def _theta_panel(ax: Axes, trace: Trace) -> None:
    """θ(t) [deg], desired dashed grey (label ``"θ desired"``) and actual solid black."""
    t = trace.t
    theta_des, theta = np.degrees(trace.desired_pose[:, 2]), np.degrees(trace.object_pose[:, 2])
    ax.plot(t, theta, color=ACTUAL_COLOUR, lw=2.0, label="θ actual")
    ax.plot(t, theta_des, color=DESIRED_COLOUR, lw=1.6, ls="--", label="θ desired")
    if max(np.ptp(theta_des), np.ptp(theta)) < 1.0:  # a straight push: no ±0.04° axis
        mid = 0.5 * (theta.mean() + theta_des.mean())
        ax.set_ylim(mid - 1.0, mid + 1.0)
    ax.set_ylabel("θ [deg]")
    ax.legend(fontsize=FONT["legend"], loc="best")
    ax.set_title("rotation", fontsize=FONT["label"])


def _error_panel(ax: Axes, trace: Trace) -> Axes:
    """‖p − p_des‖(t) [mm] on the left axis (black); θ − θ_des [deg] on a twin right axis
    (blue). θ is continuous (not wrapped), so the difference is the error. Returns the
    twin."""
    t = trace.t
    diff = trace.object_pose - trace.desired_pose
    position = np.hypot(diff[:, 0], diff[:, 1]) * MM
    angle = np.degrees(diff[:, 2])
    ax.plot(t, position, color=ACTUAL_COLOUR, lw=1.5, label="‖p − p_des‖")
    ax.set_ylabel("position error [mm]")
    ax.set_ylim(0.0, max(float(position.max()), 1e-3) * 1.1)
    twin = ax.twinx()
    twin.plot(t, angle, color=RATE_COLOUR, lw=1.3, label="θ − θ_des")
    twin.axhline(0.0, color=RATE_COLOUR, lw=0.6, alpha=0.5)
    bound = max(float(np.abs(angle).max()), 0.05) * 1.1
    twin.set_ylim(-bound, bound)
    twin.set_ylabel("angle error θ − θ_des [deg]", color=RATE_COLOUR, fontsize=FONT["label"])
    twin.tick_params(axis="y", colors=RATE_COLOUR, labelsize=FONT["tick"])
    handles = ax.get_lines() + twin.get_lines()[:1]
    ax.legend(handles=handles, fontsize=FONT["legend"], loc="upper left")
    ax.set_title("tracking error", fontsize=FONT["label"])
    return twin


def _force_panel(ax: Axes, trace: Trace, component: int) -> None:
    """Per-prong ``component`` (0 normal, 1 tangential) force [N] over rows 1 … N: actual
    solid (gid ``"<name>_actual_<i>"``), desired dashed on top (gid ``"<name>_desired_<i>"``);
    the tangential panel adds the friction cone ±μ_c λ_n,i dotted."""
    name, sub = _FORCE_NAMES[component]
    t = trace.t[1:]
    actual, desired = trace.contact_forces[1:], trace.desired_forces[1:]
    for i in range(trace.n_prongs):
        colour, width = prong_colour(i), prong_line_width(i)
        (line,) = ax.plot(t, actual[:, i, component], color=colour, lw=0.75 * width, alpha=0.8)
        line.set_gid(f"{name}_actual_{i + 1}")
        line.set_label(f"$λ_{{{sub},{i + 1}}}$")
        (line,) = ax.plot(t, desired[:, i, component], color=colour, lw=width, ls="--", zorder=3)
        line.set_gid(f"{name}_desired_{i + 1}")
        line.set_label(f"$F_{{{sub},{i + 1}}}$ desired")
    steady = [desired[:, :, component]]
    handles = [_prong_handle(i) for i in range(trace.n_prongs)] + _style_handles()
    if component == 1:
        cone = trace.mu_contact * actual[:, :, 0]
        for i in range(trace.n_prongs):
            for sign in (-1.0, 1.0):
                ax.plot(t, sign * cone[:, i], color=prong_colour(i), lw=0.8, ls=":", alpha=0.6)
        # the cone's usual reach, not its spikes, sets the limits
        steady.append(np.percentile(cone, 90.0, axis=0) * np.array([[-1.0], [1.0]]))
        label = rf"$\pm\mu_c \lambda_n$ ($\mu_c$ = {trace.mu_contact:g})"
        handles.append(Line2D([], [], color="0.3", lw=0.8, ls=":", label=label))
    ax.axhline(0.0, color="0.4", lw=0.6)
    ax.set_ylabel(f"{name} force [N]")
    ax.set_xlabel("t [s]")
    notes = _fit_ylim(ax, t, actual[:, :, component], steady, "N", (len(handles), 3))
    ax.legend(handles=handles + notes, fontsize=FONT["legend"], loc="upper left", ncol=3)
    ax.set_title(f"{name} prong forces", fontsize=FONT["label"])


def _fit_ylim(
    ax: Axes,
    t: np.ndarray,
    actual: np.ndarray,
    steady: list[np.ndarray],
    unit: str,
    legend: tuple[int, int],
) -> list[Line2D]:
    """Set the y limits to every value of ``steady`` (desired curves, shown in full) and of
    ``actual`` (N,) or (N, k) over times ``t`` (N,), with headroom on top for an upper legend
    of ``legend`` = (entries, columns), a possible note added. If a transient of ``actual``
    (say the impact at the first contact) would stretch the span more than ``CLIP_SPAN``
    fold beyond its 1st–99th percentiles, the limits clip it instead; returns a legend entry
    naming the clipped peak (else none)."""
    actual = actual.reshape(len(t), -1)
    fixed = np.concatenate([np.ravel(s) for s in steady] + [[0.0]])
    full = np.concatenate([fixed, actual.ravel()])
    core = np.concatenate([fixed, np.percentile(actual, [1.0, 99.0], axis=0).ravel()])
    low, high = float(full.min()), float(full.max())
    notes = []
    core_span = float(np.ptp(core))
    if high - low > CLIP_SPAN * max(core_span, 1e-12):
        low, high = float(core.min()), float(core.max())
        low, high = low - 0.2 * core_span, high + 0.2 * core_span
        row, col = np.unravel_index(np.argmax(np.abs(actual)), actual.shape)
        peak = f"off scale: {actual[row, col]:.3g} {unit} at t = {t[row]:.2f} s"
        notes.append(Line2D([], [], ls="none", label=peak))
    span = max(high - low, 1e-9)
    entries, columns = legend
    rows = -(-(entries + len(notes)) // columns)
    ax.set_ylim(low - 0.05 * span, high + (0.08 + 0.09 * rows) * span)
    return notes


def _prong_handle(i: int) -> Line2D:
    return Line2D([], [], color=prong_colour(i), lw=2.0, label=f"prong {i + 1}")


def _torque_panel(ax: Axes, trace: Trace) -> None:
    """Total torque τ_z about the centre of mass [N·m] over rows 1 … N: actual solid black
    (label ``"τ_z actual"``), desired dashed grey (label ``"τ_z desired"``)."""
    t = trace.t[1:]
    actual, desired = trace.contact_torque[1:], trace.desired_torque[1:]
    ax.plot(t, actual, color=ACTUAL_COLOUR, lw=1.4, label="τ_z actual")
    ax.plot(t, desired, color=DESIRED_COLOUR, lw=1.6, ls="--", label="τ_z desired")
    ax.axhline(0.0, color="0.4", lw=0.6)
    ax.set_ylabel("torque τ_z [N·m]")
    ax.set_xlabel("t [s]")
    handles, _ = ax.get_legend_handles_labels()
    handles += _fit_ylim(ax, t, actual, [desired], "N·m", (len(handles), 1))
    ax.legend(handles=handles, fontsize=FONT["legend"], loc="upper left")
    ax.set_title("total torque about the CoM", fontsize=FONT["label"])


def _title(trace: Trace) -> str:
    diff = trace.object_pose[-1] - trace.desired_pose[-1]
    return (
        f"push trace · {trace.n_prongs} prong{'s' if trace.n_prongs != 1 else ''} · "
        f"T = {trace.t[-1] - trace.t[0]:.2f} s · μ_c = {trace.mu_contact:g} · "
        f"arc {trace.arc_length * MM:.0f} mm · Δθ = {_degrees(trace.delta_theta, 1)}° · "
        f"final error {np.hypot(diff[0], diff[1]) * MM:.1f} mm, {_degrees(diff[2], 2)}°"
    )


def trace_figure(trace: Trace, title: str | None = None) -> Figure:
    """A (15 × 8 in) figure of ``trace``, six panels in a 2 × 3 grid: top view [mm], θ(t)
    [deg], tracking errors [mm, deg] (with a twin axis: 7 axes in all); normal and
    tangential prong forces [N] and the total torque τ_z [N·m], actual solid and desired
    dashed. ``title`` replaces the default summary (prongs, duration, μ_c, the plan's arc and
    Δθ, the final error). Returns the figure without showing or saving it."""
    fig = Figure(figsize=(15, 8), layout="constrained")
    grid = fig.add_gridspec(2, 3)
    path = fig.add_subplot(grid[0, 0])
    theta = fig.add_subplot(grid[0, 1])
    error = fig.add_subplot(grid[0, 2], sharex=theta)
    normal = fig.add_subplot(grid[1, 0], sharex=theta)
    tangential = fig.add_subplot(grid[1, 1], sharex=theta)
    torque = fig.add_subplot(grid[1, 2], sharex=theta)
    _path_panel(path, trace)
    _theta_panel(theta, trace)
    _error_panel(error, trace)
    _force_panel(normal, trace, 0)
    _force_panel(tangential, trace, 1)
    _torque_panel(torque, trace)
    for ax in (path, theta, error, normal, tangential, torque):
        ax.grid(True, color="0.88", lw=0.6)
        ax.tick_params(labelsize=FONT["tick"])
        ax.xaxis.label.set_fontsize(FONT["label"])
        ax.yaxis.label.set_fontsize(FONT["label"])
    for ax in (theta, error):
        ax.set_xlabel("t [s]", fontsize=FONT["label"])
    theta.set_xlim(trace.t[0], trace.t[-1])
    fig.suptitle(_title(trace) if title is None else title, fontsize=FONT["title"])
    return fig


def _degrees(radians: float, digits: int) -> str:
    """``radians`` in degrees with a sign, ``digits`` decimals; a value that rounds to zero
    is ``0.00``, not ``-0.00``."""
    value = round(float(np.degrees(radians)), digits) + 0.0  # + 0.0 turns -0.0 into 0.0
    return f"{value:+.{digits}f}" if value else f"{0.0:.{digits}f}"
