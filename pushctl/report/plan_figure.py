"""One-figure summary of a push plan, for talks and papers.

Left: a top view in millimetres (world frame, arm base at the origin) of the centre-of-mass
arc from start to goal, the instant centre of rotation (ICR) with its radii, and the object,
pusher plate and prong contacts at a few evenly spaced instants. Right, sharing the time
axis [s]: θ [deg] with ω [deg/s] (the CoM speed [mm/s] for a straight push), the desired
normal and tangential prong forces [N] with the friction cone ±μ_c F_n, and the prong and
total torques about the centre of mass [N·m].

The figure is a bare :class:`matplotlib.figure.Figure` (no pyplot, no global state): save
it with ``fig.savefig(path)``.
"""

from __future__ import annotations

import math
import textwrap
from typing import TYPE_CHECKING

import numpy as np
from matplotlib import colormaps
from matplotlib.axes import Axes
from matplotlib.colors import Colormap
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from pushctl.objects import polygon_world, to_world

if TYPE_CHECKING:
    from pushctl.planning import Plan

MM = 1e3
"""Metres to millimetres (the top view is drawn in mm)."""
PRONG_COLOURS = ("#d62728", "#2ca02c", "#9467bd", "#ff7f0e")
"""One colour per prong (up to 4), used in every panel."""
FAR_ICR = 3.0
"""An ICR farther than this many plot extents from the path is only named in the legend."""
RATE_COLOUR = "#1f77b4"
"""Colour of the rotation rate (and its axis)."""
FONT = {"title": 12, "label": 10, "tick": 9, "legend": 8}


def _plate_outline(plan: Plan) -> np.ndarray:
    """Local corners (4, 2) [m] of the plate: flush behind the pushed face at the offset δ."""
    pusher = plan.pusher
    x0 = -plan.obj.face_offset
    x1 = x0 - pusher.thickness
    y0, y1 = plan.forces.offset - 0.5 * pusher.width, plan.forces.offset + 0.5 * pusher.width
    return np.array([[x0, y0], [x0, y1], [x1, y1], [x1, y0]])


def _draw_bodies(ax: Axes, plan: Plan, outlines: int, cmap: Colormap) -> np.ndarray:
    """Object, plate (the plan's pusher, width × thickness) and prongs (gid ``"prong_i"``) at
    ``outlines`` instants evenly spaced in time, light → dark, later ones on top; returns
    every drawn world point (P, 2) [m] for the axis limits."""
    pose = plan.trajectory.pose
    plate = _plate_outline(plan)
    drawn = [pose[:, :2]]
    steps = np.linspace(0, len(pose) - 1, max(outlines, 1)).round().astype(int)
    for j, step in enumerate(steps):
        shade, z = 0.35 + 0.6 * j / max(len(steps) - 1, 1), 2.0 + 0.01 * j
        body = polygon_world(plan.obj, pose[step])
        slab = to_world(pose[step], plate)
        ax.fill(*body.T * MM, fc=cmap(shade), alpha=0.15, zorder=z)
        ax.fill(*body.T * MM, fill=False, ec=cmap(shade), lw=1.2, zorder=z)
        ax.fill(*slab.T * MM, fc="0.75", ec="0.3", lw=0.7, alpha=0.8, zorder=z)
        for i, point in enumerate(to_world(pose[step], plan.forces.prong_points)):
            colour = PRONG_COLOURS[i % len(PRONG_COLOURS)]
            (dot,) = ax.plot(*point * MM, "o", ms=5, mfc=colour, mec="white", mew=0.6, zorder=3)
            dot.set_gid(f"prong_{i + 1}")
        drawn += [body, slab]
    return np.vstack(drawn)


def _draw_icr(ax: Axes, plan: Plan, extent: np.ndarray) -> str | None:
    """Mark the ICR with its radii to start and goal if it lies within ``FAR_ICR`` extents
    of the drawn points ``extent`` (P, 2) [m]; else return a note for the legend."""
    tr = plan.trajectory
    if tr.icr is None:
        return "straight push (no ICR)"
    size = float(np.ptp(extent, axis=0).max())
    gap = np.maximum(np.maximum(extent.min(axis=0) - tr.icr, tr.icr - extent.max(axis=0)), 0.0)
    label = f"ICR, R = {tr.radius * MM:.0f} mm"
    if float(np.hypot(*gap)) > FAR_ICR * size:
        return label + " (off plot)"
    for end in (tr.pose[0, :2], tr.pose[-1, :2]):
        ax.plot(*np.column_stack([tr.icr, end]) * MM, ls="--", lw=0.9, color="0.5", zorder=1)
    ax.plot(*tr.icr * MM, "P", ms=9, color="#8c564b", label=label, zorder=5)
    return None


def _draw_push_arrow(ax: Axes, plan: Plan, size: float) -> np.ndarray:
    """Arrow behind the start plate along the centre of mass's initial direction; returns
    its tail [m] (for the axis limits)."""
    tangent = plan.trajectory.path_tangent[0]
    direction = tangent / max(float(np.linalg.norm(tangent)), 1e-12)
    back = plan.pusher_positions[0, :2] - direction * plan.pusher.thickness
    tail, head = back - direction * 0.16 * size, back - direction * 0.01 * size
    arrow = {"arrowstyle": "-|>", "color": "0.2", "lw": 1.8, "shrinkA": 0, "shrinkB": 0}
    ax.annotate("", xy=tuple(head * MM), xytext=tuple(tail * MM), arrowprops=arrow, zorder=6)
    ax.annotate(
        "push", xy=tuple(0.5 * (head + tail) * MM), xytext=(0, 4), textcoords="offset points",
        ha="center", va="bottom", fontsize=FONT["legend"], color="0.2",
    )  # fmt: skip
    return tail


def _map_panel(ax: Axes, plan: Plan, outlines: int) -> None:
    """Top view of the push [mm], equal aspect; the CoM path line has gid ``"com_path"``."""
    tr = plan.trajectory
    extent = _draw_bodies(ax, plan, outlines, colormaps["Blues"])
    (path,) = ax.plot(*tr.pose[:, :2].T * MM, color="k", lw=2.0, label="CoM path", zorder=4)
    path.set_gid("com_path")
    ax.plot(*tr.pose[0, :2] * MM, "o", ms=7, mfc="white", mec="k", label="start", zorder=5)
    ax.plot(*tr.pose[-1, :2] * MM, "*", ms=13, color="#e6a100", mec="k", label="goal", zorder=5)
    note = _draw_icr(ax, plan, extent)
    tail = _draw_push_arrow(ax, plan, float(np.ptp(extent, axis=0).max()))
    ax.update_datalim([tuple(tail * MM)])
    ax.set_aspect("equal", adjustable="datalim")
    ax.margins(0.05)
    ax.autoscale_view()
    handles, _ = ax.get_legend_handles_labels()
    handles += [_prong_handle(i) for i in range(len(plan.forces.prong_points))]
    if note:
        handles.append(Line2D([], [], ls="none", label=note))
    ax.legend(handles=handles, fontsize=FONT["legend"], loc="best", framealpha=0.85)
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")


def _prong_handle(i: int) -> Line2D:
    colour = PRONG_COLOURS[i % len(PRONG_COLOURS)]
    return Line2D([], [], marker="o", ls="none", mfc=colour, mec="white", label=f"prong {i + 1}")


def _rotation_panel(ax: Axes, plan: Plan) -> None:
    """θ(t) [deg] on the left axis (black); ω(t) [deg/s], or the speed [mm/s] of a straight
    push, on a twin right axis (blue)."""
    tr = plan.trajectory
    theta = np.degrees(tr.pose[:, 2])
    ax.plot(tr.t, theta, color="k", lw=1.8)
    ax.set_ylabel("θ [deg]")
    if np.ptp(theta) < 1.0:  # a straight push: no ±0.04° axis
        ax.set_ylim(theta.mean() - 1.0, theta.mean() + 1.0)
    twin = ax.twinx()
    if tr.icr is None:
        rate, label = np.hypot(*tr.velocity[:, :2].T) * MM, "speed |v| [mm/s]"
    else:
        rate, label = np.degrees(tr.velocity[:, 2]), "ω [deg/s]"
    twin.plot(tr.t, rate, color=RATE_COLOUR, lw=1.3)
    twin.set_ylabel(label, color=RATE_COLOUR, fontsize=FONT["label"])
    twin.tick_params(axis="y", colors=RATE_COLOUR, labelsize=FONT["tick"])
    low, high = min(0.0, float(rate.min())), max(0.0, float(rate.max()))
    pad = 0.08 * (high - low) if high > low else 1.0
    twin.set_ylim(low - pad, high + pad)


def _force_panel(ax: Axes, plan: Plan) -> None:
    """Desired normal (solid) and tangential (dashed) prong forces [N]; the plan's friction
    cone ±μ_c F_n,i shaded grey."""
    t, forces = plan.trajectory.t, plan.forces.forces
    mu_contact = plan.settings.mu_contact
    for i in range(forces.shape[1]):
        colour, width = prong_colour(i), prong_line_width(i)
        normal, tangential = forces[:, i, 0], forces[:, i, 1]
        ax.plot(t, normal, color=colour, lw=width, label=f"$F_{{n,{i + 1}}}$")
        ax.plot(t, tangential, color=colour, lw=width, ls="--", label=f"$F_{{t,{i + 1}}}$")
        bound = mu_contact * normal
        ax.fill_between(t, -bound, bound, color="0.5", alpha=0.12, lw=0)
    ax.fill_between([], [], [], color="0.5", alpha=0.25, lw=0, label=f"±{mu_contact:g} $F_n$")
    ax.axhline(0.0, color="0.4", lw=0.6)
    ax.set_ylabel("force [N]")
    ax.legend(loc="upper left", ncol=5, fontsize=FONT["legend"])
    _headroom(ax)


def prong_colour(prong: int) -> str:
    """Colour of prong ``prong`` (0-based), cycling through :data:`PRONG_COLOURS`."""
    return PRONG_COLOURS[prong % len(PRONG_COLOURS)]


def prong_line_width(prong: int) -> float:
    """Line width [pt] of prong ``prong``: later prongs thinner, so equal curves all show."""
    return max(2.4 - 0.7 * prong, 0.8)


def _torque_panel(ax: Axes, plan: Plan) -> None:
    """Per-prong torques τ_z,i and their sum τ_z,des [N·m] about the centre of mass."""
    t, torques = plan.trajectory.t, plan.forces.torques
    for i in range(torques.shape[1]):
        colour = PRONG_COLOURS[i % len(PRONG_COLOURS)]
        ax.plot(t, torques[:, i], color=colour, lw=prong_line_width(i), label=f"$τ_{{z,{i + 1}}}$")
    ax.plot(t, plan.forces.total_torque, color="k", lw=1.8, label="$τ_{z,des}$")
    ax.axhline(0.0, color="0.4", lw=0.6)
    ax.set_ylabel("torque [N·m]")
    ax.set_xlabel("t [s]")
    ax.legend(loc="upper left", ncol=4, fontsize=FONT["legend"])
    _headroom(ax)


def _headroom(ax: Axes, fraction: float = 0.35) -> None:
    """Raise the top y limit so an upper-left legend sits above the curves."""
    low, high = ax.get_ylim()
    ax.set_ylim(low, high + fraction * (high - low))


def _title(plan: Plan) -> str:
    tr, fp = plan.trajectory, plan.forces
    verdict = "feasible" if plan.feasible else "INFEASIBLE (see below)"
    return (
        f"{plan.obj.name} · {tr.profile} profile · Δθ = {_degrees(tr.delta_theta)}° · "
        f"arc {tr.arc_length * MM:.0f} mm · prong offset δ = {fp.offset * MM:+.1f} mm · "
        f"{verdict}"
    )


def plan_figure(plan: Plan, outlines: int = 6) -> Figure:
    """A (13 × 7 in) figure of ``plan``: top view [mm] left, θ/ω, prong forces [N] with the
    friction cone and torques [N·m] over t [s] right. ``outlines`` (≥ 1) instants of the
    object are drawn. Returns the figure without showing or saving it."""
    fig = Figure(figsize=(13, 7), layout="constrained")
    grid = fig.add_gridspec(3, 2, width_ratios=(1.0, 1.05), height_ratios=(1.0, 1.2, 1.0))
    top = fig.add_subplot(grid[:, 0])
    rotation = fig.add_subplot(grid[0, 1])
    forces = fig.add_subplot(grid[1, 1], sharex=rotation)
    torques = fig.add_subplot(grid[2, 1], sharex=rotation)
    _map_panel(top, plan, outlines)
    _rotation_panel(rotation, plan)
    _force_panel(forces, plan)
    _torque_panel(torques, plan)
    for ax in (top, rotation, forces, torques):
        ax.grid(True, color="0.88", lw=0.6)
        ax.tick_params(labelsize=FONT["tick"])
        ax.xaxis.label.set_fontsize(FONT["label"])
        ax.yaxis.label.set_fontsize(FONT["label"])
    for ax in (rotation, forces):
        ax.tick_params(labelbottom=False)
    rotation.set_xlim(plan.trajectory.t[0], plan.trajectory.t[-1])
    fig.suptitle(_title(plan), fontsize=FONT["title"])
    if plan.problems:
        caption = textwrap.fill(plan.problems[0], 190)
        fig.supxlabel(caption, fontsize=FONT["legend"], color="#b00000")
    return fig


def _degrees(radians: float) -> str:
    """``radians`` in degrees with a sign and one decimal; ``0.0``, not ``-0.0``."""
    value = round(math.degrees(radians), 1) + 0.0
    return f"{value:+.1f}" if value else "0.0"
