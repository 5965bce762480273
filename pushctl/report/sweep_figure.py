"""A sweep's figure: the validation score of every run against each swept key's value.

One panel per key: each run (configuration × seed) a point, the mean over the runs at each
value a bar, joined by a line for a grid (a random search's values are draws: no trend is
drawn through them); a dashed line at 2, the score of PD-only (force and translation ratio 1
each). Lower is better. A key whose positive values span more than a factor 10 is drawn on a
log axis.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from pushctl.report.figures import PD, RL, _style_axes

PD_SCORE = 2.0
LOG_SPAN = 10.0


def sweep_figure(trials: pd.DataFrame, keys: list[str], grid: bool = True) -> Figure:
    """``trials``: :class:`~pushctl.runs.sweep.SweepResult`'s rows (columns
    ``score`` and each of ``keys``); ``grid``: the search was a grid."""
    figure = Figure(figsize=(4.2 * len(keys), 3.6), layout="constrained")
    axes = figure.subplots(1, len(keys), squeeze=False)[0]
    for ax, key in zip(axes, keys, strict=True):
        values = trials[key]
        numeric = pd.api.types.is_numeric_dtype(values) and not pd.api.types.is_bool_dtype(values)
        x = values if numeric else values.astype(str)
        ax.scatter(x, trials["score"], s=18, color=RL, alpha=0.7, label="run (one seed)")
        means = trials.groupby(x, sort=True)["score"].mean()
        ax.plot(
            means.index,
            means.to_numpy(),
            color=RL,
            lw=1.5 if grid else 0.0,
            marker="_",
            markersize=14,
            label="mean at the value",
        )
        ax.axhline(PD_SCORE, color=PD, ls="--", lw=1.2, label="PD-only")
        positive = np.asarray(values[values > 0] if numeric else [], dtype=float)
        if numeric and len(positive) == len(values) and positive.max() > LOG_SPAN * positive.min():
            ax.set_xscale("log")
        elif numeric:
            ax.locator_params(axis="x", nbins=5)
        ax.set_xlabel(key)
        ax.set_ylabel("validation score (force + translation ratio)")
        _style_axes(ax)
    axes[0].legend(fontsize="small")
    return figure
