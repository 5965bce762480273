"""The paper's Figs. 5, 6 and 8 from the training curve and the per-step evaluation means.

- :func:`training_figure` (Fig. 5): per-episode normal force, tangential force and torque
  error during training, PD-only against RL-assisted: each episode a faint point, a rolling
  mean over episodes on top.
- :func:`tracking_figure` (Fig. 6): desired, PD-only and RL-assisted translation and angle
  over time, mean over the trials, with their tracking errors below; one column per profile,
  objects as line styles.
- :func:`force_error_figure` (Fig. 8): per-step force and torque error, mean over the
  trials, PD-only against RL-assisted, ``sim`` against ``proxy``; one column per profile,
  two rows per object.

Colours follow the paper: desired green, PD-only blue, RL-assisted red; each controller's
colour, line width and legend label are its registry entry's
(:mod:`pushctl.controllers`). Each function takes
the checked frames of :mod:`pushctl.report.inputs` and returns a bare
:class:`matplotlib.figure.Figure` (no pyplot, no global state); the caller saves it.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from pushctl.controllers import controller_entry, controller_names
from pushctl.report.plan_figure import FONT
from pushctl.report.tables import OBJECT_ORDER, PROFILE_ORDER, ordered_names

DESIRED = "#2ca02c"
PD = controller_entry("pd").colour
RL = controller_entry("rl").colour
PD_PROXY = "#7fb8e6"
RL_PROXY = "#f29a4a"
OBJECT_STYLES = ("-", "--", ":", "-.")
"""Line style of each object, in :data:`OBJECT_ORDER` (others after)."""
LOG_SPAN = 100.0
"""A panel whose positive values span more than this factor is drawn on a log scale."""
MILLI = 1e3
"""N → mN and N·m → mN·m: the figures show forces and torques in milli-units (the CSVs
hold SI), so no axis needs a 1e−5 offset."""
SMOOTH_S = 0.25
"""Fig. 8's bold lines: centred rolling mean over this many seconds of steps."""

_CURVE_PANELS = (
    ("force_n_error", r"normal force error $|\Delta F_n|$ [mN]"),
    ("force_t_error", r"tangential force error $|\Delta F_t|$ [mN]"),
    ("torque_error", r"torque error $|\Delta\tau_z|$ [mN·m]"),
)


def _style_axes(ax: Axes) -> None:
    ax.grid(True, color="0.88", lw=0.6)
    ax.tick_params(labelsize=FONT["tick"])
    ax.xaxis.label.set_fontsize(FONT["label"])
    ax.yaxis.label.set_fontsize(FONT["label"])


def _log_if_wide(ax: Axes, values: np.ndarray) -> None:
    """Log y scale when the positive finite ``values`` span more than :data:`LOG_SPAN`."""
    positive = values[np.isfinite(values) & (values > 0)]
    if positive.size and positive.max() > LOG_SPAN * positive.min():
        ax.set_yscale("log")


def rolling_mean(episode: np.ndarray, values: np.ndarray, window: int) -> np.ndarray:
    """Centred rolling mean of ``values`` (n,) at ``episode`` (n,) over about ``window``
    episodes, with triangular weights (an outlier fades in and out instead of making a
    step). A series present on every k-th episode (PD-only) averages ``window / k`` points:
    the same span of training as a series present on every one."""
    if values.size == 0:
        return values
    gaps = np.diff(episode)
    step = float(np.median(gaps)) if gaps.size else 1.0
    points = max(1, round(window / max(step, 1.0)))
    series = pd.Series(values)
    if points < 3:
        return series.to_numpy(float)
    rolling = series.rolling(
        points, center=True, min_periods=max(1, points // 2), win_type="triang"
    )
    return rolling.mean().to_numpy(float)


def training_figure(curve: pd.DataFrame, window: int = 100) -> Figure:
    """Fig. 5 from ``curve`` (the columns of ``training/curve.csv``): three panels over the
    episode, normal and tangential force error [mN] and torque error [mN·m] of each RL
    episode (red, exploration noise included) and PD-only episode (blue, on the episodes
    where it ran), raw points faint and a centred rolling mean over ``window`` episodes
    solid. A run shorter than five windows is averaged over a fifth of its episodes (at
    least 3), so a short run's line follows it rather than flattening into one hump."""
    window = min(window, max(3, len(curve) // 5))
    fig = Figure(figsize=(11, 9), layout="constrained")
    axes = fig.subplots(len(_CURVE_PANELS), 1, sharex=True)
    counts = {}
    for ax, (metric, label) in zip(axes, _CURVE_PANELS, strict=True):
        shown = []
        for controller in ("rl", "pd"):  # PD-only's fewer points on top
            rows = curve[["episode", f"{controller}_{metric}"]].dropna()
            episode = rows["episode"].to_numpy(float)
            values = MILLI * rows[f"{controller}_{metric}"].to_numpy(float)
            counts[controller] = len(rows)
            colour = controller_entry(controller).colour
            alpha = 0.45 if controller == "pd" else 0.2
            ax.plot(episode, values, ".", ms=3, color=colour, alpha=alpha, mew=0, zorder=1)
            ax.plot(episode, rolling_mean(episode, values, window), color=colour, lw=1.8, zorder=3)
            shown.append(values)
        _log_if_wide(ax, np.concatenate(shown))
        ax.set_ylabel(label)
        _style_axes(ax)
    axes[-1].set_xlabel("training episode")
    handles = []
    for controller in ("pd", "rl"):
        colour, name = controller_entry(controller).colour, controller_entry(controller).label
        raw = f"{name}, one episode ({counts[controller]} episodes)"
        handles.append(Line2D([], [], ls="none", marker=".", color=colour, alpha=0.5, label=raw))
        handles.append(Line2D([], [], color=colour, lw=1.8, label=f"{name}, rolling mean"))
    fig.legend(handles=handles, loc="outside lower center", ncol=4, fontsize=FONT["legend"] + 1)
    fig.suptitle(
        "Fig. 5 · training: per-episode mean absolute tracking errors, PD-only vs RL-assisted "
        f"(exploration noise included)\nlines: rolling mean over {window} episodes",
        fontsize=FONT["title"],
    )
    return fig


def _legend_columns(fig: Figure, wanted: int) -> int:
    """``wanted`` legend columns, or as many as the figure's width holds (2.2 in each): a
    one-column figure's legend wraps instead of running off its sides."""
    return max(1, min(wanted, int(fig.get_figwidth() // 2.2)))


def _fitted(fig: Figure, title: str) -> str:
    """``title`` wrapped to the figure's width (about 11 characters an inch at the title's
    size): a narrow figure's title wraps instead of being cut at its sides."""
    import textwrap

    return textwrap.fill(title, width=max(30, int(fig.get_figwidth() * 11)))


def _pick_plant(steps: pd.DataFrame, plant: str) -> tuple[pd.DataFrame, str]:
    """The rows of ``plant``, or of the other plant (named in the title) if it has none."""
    rows = steps[steps["plant"] == plant]
    if rows.empty:
        other = str(steps["plant"].iloc[0])
        return steps[steps["plant"] == other], f"{other} plant (no {plant} rows)"
    return rows, f"{plant} plant"


def _object_styles(steps: pd.DataFrame) -> dict[str, str]:
    objects = ordered_names(steps["object"], OBJECT_ORDER)
    return {obj: OBJECT_STYLES[i % len(OBJECT_STYLES)] for i, obj in enumerate(objects)}


_TRACKING_ROWS = (
    ("translation_mm", "translation_des_mm", "translation from start [mm]"),
    ("translation_error_mm", None, r"translation error $\|p - p_{des}\|$ [mm]"),
    ("angle_deg", "angle_des_deg", r"rotation $(\theta - \theta_0)\,$sign$(\Delta\theta)$ [deg]"),
    ("angle_error_deg", None, r"angle error $|\theta - \theta_{des}|$ [deg]"),
)


def tracking_figure(steps: pd.DataFrame, plant: str = "sim") -> Figure:
    """Fig. 6 from ``steps`` (the columns of ``evaluation/steps.csv``) on ``plant``: rows
    translation [mm], translation error [mm], rotation [deg] and angle error [deg] over t
    [s]; one column per profile; desired green, PD-only blue, feedback purple, RL-assisted
    red; one line style per object. Each line is the mean over the trials of its (object,
    profile)."""
    rows, plant_text = _pick_plant(steps, plant)
    profiles = ordered_names(rows["profile"], PROFILE_ORDER)
    styles = _object_styles(rows)
    fig = Figure(figsize=(4.4 * len(profiles) + 1.5, 10.5), layout="constrained")
    axes = fig.subplots(len(_TRACKING_ROWS), len(profiles), sharex="col", squeeze=False)
    for col, profile in enumerate(profiles):
        for obj, style in styles.items():
            cell = rows[(rows["profile"] == profile) & (rows["object"] == obj)]
            for row, (actual, desired, _) in enumerate(_TRACKING_ROWS):
                _draw_tracking(axes[row, col], cell, actual, desired, style)
        axes[0, col].set_title(f"{profile} profile", fontsize=FONT["label"])
        axes[-1, col].set_xlabel("t [s]")
    for row, (_, desired, label) in enumerate(_TRACKING_ROWS):
        axes[row, 0].set_ylabel(label)
        if desired is None:  # an error row: from zero, so sizes compare at a glance
            for ax in axes[row]:
                ax.set_ylim(bottom=0.0)
    for ax in axes.flat:
        _style_axes(ax)
    fig.legend(
        handles=_tracking_handles(styles, set(rows["controller"])),
        loc="outside lower center",
        ncol=_legend_columns(fig, 4 + len(styles)),
        fontsize=FONT["legend"] + 1,
    )
    fig.suptitle(
        _fitted(
            fig,
            f"Fig. 6 · tracking, mean over the trials ({plant_text}): desired vs PD-only vs "
            "feedback vs RL-assisted",
        ),
        fontsize=FONT["title"],
    )
    return fig


def _draw_tracking(
    ax: Axes, cell: pd.DataFrame, actual: str, desired: str | None, style: str
) -> None:
    """One object's ``actual`` curve of each controller, in the registry's order (PD-only
    wide underneath, RL-assisted narrow on top; and the ``desired`` one, if named, once)
    in ``ax``."""
    for controller in controller_names():
        line = cell[cell["controller"] == controller].sort_values("step")
        if line.empty:
            continue
        if desired is not None and controller == _first_controller(cell):
            ax.plot(line["t"], line[desired], color=DESIRED, lw=4.5, ls=style, alpha=0.45)
        entry = controller_entry(controller)
        ax.plot(line["t"], line[actual], color=entry.colour, lw=entry.width, ls=style)


def _first_controller(cell: pd.DataFrame) -> str:
    """The controller whose rows draw the desired curve (every controller tracks the same
    paired plans): the first present in the registry's order."""
    present = set(cell["controller"])
    return next(c for c in controller_names() if c in present)


def _tracking_handles(styles: dict[str, str], controllers: set[str]) -> list[Line2D]:
    handles = [Line2D([], [], color=DESIRED, lw=4.5, alpha=0.45, label="desired")]
    handles += [
        Line2D([], [], color=entry.colour, lw=entry.width, label=entry.label)
        for entry in map(controller_entry, controller_names())
        if entry.name in controllers
    ]
    handles += [Line2D([], [], color="0.3", ls=s, lw=1.3, label=o) for o, s in styles.items()]
    return handles


_FORCE_ROWS = (
    ("force_error", r"force error $\|F_{des} - \lambda\|$ [mN]"),
    ("torque_error", r"torque error $|\Delta\tau_z|$ [mN·m]"),
)
_SERIES = (
    ("pd", "sim", PD, "-"),
    ("pd", "proxy", PD_PROXY, "--"),
    ("rl", "sim", RL, "-"),
    ("rl", "proxy", RL_PROXY, "--"),
    ("pd", "mujoco", PD, ":"),  # drawn only when the steps have mujoco rows
    ("rl", "mujoco", RL, ":"),
)


def _smooth(t: np.ndarray, values: np.ndarray, seconds: float) -> np.ndarray:
    """Centred rolling mean of ``values`` (n,) sampled at ``t`` (n,) [s] over ``seconds``."""
    if values.size < 3:
        return values
    points = max(1, round(seconds / max(float(np.median(np.diff(t))), 1e-9)))
    series = pd.Series(values).rolling(points, center=True, min_periods=1)
    return series.mean().to_numpy(float)


def _force_panel(ax: Axes, cell: pd.DataFrame, metric: str, smooth: float) -> None:
    """The four series of one (object, profile) ``cell`` of the steps: each step thin and
    faint, a ``smooth``-second rolling mean bold. Steps 1 … N only, as in the metrics:
    step 0 is the approach's last, the prongs only just touching, its force error the
    whole planned force."""
    drawn = [np.array([], dtype=float)]
    for controller, plant, colour, style in _SERIES:
        line = cell[(cell["controller"] == controller) & (cell["plant"] == plant)]
        if plant == "mujoco" and line.empty:
            continue
        line = line[line["step"] > 0].sort_values("step")
        t, values = line["t"].to_numpy(float), MILLI * line[metric].to_numpy(float)
        ax.plot(t, values, color=colour, lw=0.5, alpha=0.3)
        width = controller_entry(controller).width
        ax.plot(t, _smooth(t, values, smooth), color=colour, ls=style, lw=width)
        drawn.append(values)
    _log_if_wide(ax, np.concatenate(drawn))


def _plants_named(steps: pd.DataFrame) -> str:
    """The plants Fig. 8 draws, in its legend's order, for its title: "sim vs proxy",
    "sim vs proxy vs MuJoCo" (only the plants ``steps`` has rows for)."""
    shown = {"sim": "sim", "proxy": "proxy", "mujoco": "MuJoCo"}
    present = set(steps["plant"])
    return " vs ".join(name for plant, name in shown.items() if plant in present)


def force_error_figure(steps: pd.DataFrame, smooth: float = SMOOTH_S) -> Figure:
    """Fig. 8 from ``steps`` (the columns of ``evaluation/steps.csv``): per-step force
    error [mN] and torque error [mN·m], mean over the trials, over t [s]; two rows per
    object, one column per profile; PD-only blue and RL-assisted red, ``sim`` solid and
    ``proxy`` dashed in a lighter shade; each step drawn faintly, a rolling mean over
    ``smooth`` seconds bold."""
    objects = ordered_names(steps["object"], OBJECT_ORDER)
    profiles = ordered_names(steps["profile"], PROFILE_ORDER)
    n_rows = len(objects) * len(_FORCE_ROWS)
    fig = Figure(figsize=(4.4 * len(profiles) + 1.5, 2.4 * n_rows + 1.2), layout="constrained")
    axes = fig.subplots(n_rows, len(profiles), sharex="col", squeeze=False)
    for i, obj in enumerate(objects):
        for j, (metric, label) in enumerate(_FORCE_ROWS):
            row = i * len(_FORCE_ROWS) + j
            for col, profile in enumerate(profiles):
                cell = steps[(steps["object"] == obj) & (steps["profile"] == profile)]
                _force_panel(axes[row, col], cell, metric, smooth)
            axes[row, 0].set_ylabel(f"{obj}\n{label}")
    for col, profile in enumerate(profiles):
        axes[0, col].set_title(f"{profile} profile", fontsize=FONT["label"])
        axes[-1, col].set_xlabel("t [s]")
    for ax in axes.flat:
        _style_axes(ax)
    handles = [
        Line2D([], [], color=c, ls=s, lw=entry.width, label=f"{entry.label}, {p}")
        for entry, p, c, s in ((controller_entry(k), p, c, s) for k, p, c, s in _SERIES)
        if p != "mujoco" or (steps["plant"] == "mujoco").any()
    ]
    handles.append(Line2D([], [], color="0.4", lw=0.5, alpha=0.5, label="each step (faint)"))
    fig.legend(
        handles=handles,
        loc="outside lower center",
        ncol=_legend_columns(fig, 5),
        fontsize=FONT["legend"] + 1,
    )
    fig.suptitle(
        _fitted(
            fig,
            "Fig. 8 · per-step force and torque tracking error, mean over the trials: "
            f"{_plants_named(steps)}, PD-only vs RL-assisted (bold: {smooth:g} s rolling mean)",
        ),
        fontsize=FONT["title"],
    )
    return fig
