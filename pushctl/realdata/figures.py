"""Figures of a replay: predicted against recorded displacement per shape, a few pushes
drawn with both predictions, and recorded against replayed two-finger paths."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402

from pushctl.realdata.metrics import COMPONENTS, predicted, recorded  # noqa: E402

_SCALE = (1e3, 1e3, np.degrees(1.0))
_UNITS = ("dx [mm]", "dy [mm]", "dθ [deg]")


def displacement_figure(pushes: pd.DataFrame, ours: np.ndarray, zhou: np.ndarray | None):
    """One row per shape, one column per component: predicted against recorded."""
    shapes = sorted(pushes["shape"].unique())
    fig, axes = plt.subplots(len(shapes), 3, figsize=(10, 2.6 * len(shapes)), squeeze=False)
    truth = recorded(pushes)
    mine = predicted(pushes, ours)
    theirs = None if zhou is None else predicted(pushes, zhou)
    for row, shape in enumerate(shapes):
        idx = np.flatnonzero(pushes["shape"].to_numpy() == shape)
        for k in range(3):
            ax = axes[row, k]
            t = truth[idx, k] * _SCALE[k]
            if theirs is not None:
                ax.scatter(t, theirs[idx, k] * _SCALE[k], s=2, alpha=0.3, label="Zhou")
            ax.scatter(t, mine[idx, k] * _SCALE[k], s=2, alpha=0.3, label="ours")
            lim = [t.min(), t.max()]
            ax.plot(lim, lim, "k-", lw=0.6)
            ax.set_title(f"{shape}: {COMPONENTS[k]}", fontsize=8)
            ax.set_xlabel(f"recorded {_UNITS[k]}", fontsize=7)
            ax.set_ylabel(f"predicted {_UNITS[k]}", fontsize=7)
    axes[0, 0].legend(fontsize=7, markerscale=4)
    fig.tight_layout()
    return fig


def example_pushes_figure(
    pushes: pd.DataFrame, shapes: dict, ours: np.ndarray, zhou: np.ndarray | None, count: int = 6
):
    """``count`` pushes (spread over the file) drawn in the world: start (grey), recorded end
    (black), ours (blue), Zhou's (orange, dashed), and the tip's line."""
    picks = np.linspace(0, len(pushes) - 1, count).astype(int)
    fig, axes = plt.subplots(1, count, figsize=(3 * count, 3.2), squeeze=False)
    for ax, i in zip(axes[0], picks, strict=True):
        row = pushes.iloc[i]
        vertices = shapes[row["shape"]]
        poses = [
            ((row.x0, row.y0, row.theta0), "0.6", "-"),
            ((row.x1, row.y1, row.theta1), "k", "-"),
            (tuple(ours[i]), "tab:blue", "-"),
        ]
        if zhou is not None:
            poses.append((tuple(zhou[i]), "tab:orange", "--"))
        for (x, y, th), colour, style in poses:
            c, s = np.cos(th), np.sin(th)
            world = vertices @ np.array([[c, s], [-s, c]]) + (x, y)
            closed = np.vstack((world, world[:1])) * 1e3
            ax.plot(closed[:, 0], closed[:, 1], color=colour, ls=style, lw=1)
        ax.plot(np.array([row.tip_x0, row.tip_x1]) * 1e3, np.array([row.tip_y0, row.tip_y1]) * 1e3,
                "r.-", lw=0.8)  # fmt: skip
        ax.set_aspect("equal")
        ax.set_title(f"{row.push_id}", fontsize=7)
        _label_mm(ax)
    entries = [("0.6", "-", "start"), ("k", "-", "recorded end"), ("tab:blue", "-", "ours")]
    if zhou is not None:
        entries.append(("tab:orange", "--", "Zhou"))
    handles = [Line2D([], [], color=c, ls=s, lw=1, label=name) for c, s, name in entries]
    handles.append(Line2D([], [], color="r", marker=".", lw=0.8, label="pusher tip"))
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=7)
    fig.suptitle("recorded pushes: the object's outline at the start and the end", fontsize=8)
    fig.tight_layout(rect=(0, 0.08, 1, 1))
    return fig


def _label_mm(ax) -> None:  # noqa: ANN001 (a matplotlib Axes)
    ax.set_xlabel("x [mm]", fontsize=7)
    ax.set_ylabel("y [mm]", fontsize=7)
    ax.tick_params(labelsize=6)


def logs_figure(segments, replays, count: int = 6):
    """Recorded (black) and replayed (blue) object paths of the first log of each start."""
    firsts: list = []
    seen: set[str] = set()
    for seg, rep in zip(segments, replays, strict=True):
        if seg.start not in seen or seg.log == firsts[-1][0].log:
            seen.add(seg.start)
            firsts.append((seg, rep))
    starts = sorted({s.start for s, _ in firsts})[:count]
    fig, axes = plt.subplots(1, len(starts), figsize=(3.2 * len(starts), 3.4), squeeze=False)
    for ax, start in zip(axes[0], starts, strict=True):
        for seg, rep in firsts:
            if seg.start != start:
                continue
            ax.plot(seg.object[:, 0] * 1e3, seg.object[:, 1] * 1e3, "k-", lw=1)
            ax.plot(rep[:, 0] * 1e3, rep[:, 1] * 1e3, color="tab:blue", lw=1)
            ax.plot(seg.pusher[:, 0] * 1e3, seg.pusher[:, 1] * 1e3, color="0.7", lw=0.6)
        ax.set_aspect("equal")
        ax.set_title(start, fontsize=7)
        _label_mm(ax)
    handles = [
        Line2D([], [], color=c, lw=w, label=name)
        for c, w, name in (("k", 1, "object centre, recorded"), ("tab:blue", 1,
                           "object centre, replayed"), ("0.7", 0.6, "pusher"))
    ]  # fmt: skip
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=7)
    fig.suptitle("two-finger logs: the first log of each start", fontsize=8)
    fig.tight_layout(rect=(0, 0.1, 1, 1))
    return fig
