"""Figures of small inputs read as well as the shipped ones: a one-cell report's titles
and legends inside the figure, a short run's Fig. 5 line following its episodes, no
``-0.00°``, and the recorded pushes' figures with axis labels and a legend entry for every
line."""

from __future__ import annotations

import numpy as np
import pandas as pd
from synthetic_results import curve_frame, steps_frame

from pushctl.report.figures import (
    force_error_figure,
    tracking_figure,
    training_figure,
)


def _inside(fig, artist) -> bool:
    fig.canvas.draw()
    box, page = artist.get_window_extent(), fig.bbox
    return box.x0 >= page.x0 - 1 and box.x1 <= page.x1 + 1


def test_a_one_cell_reports_titles_and_legends_fit_its_figures():
    steps = steps_frame()
    one = steps[(steps["object"] == "cube") & (steps["profile"] == "chirp")]
    for fig in (tracking_figure(one), force_error_figure(one)):
        assert _inside(fig, fig._suptitle)
        assert all(_inside(fig, legend) for legend in fig.legends)


def test_fig8s_title_names_the_plants_it_draws():
    steps = steps_frame()
    title = force_error_figure(steps)._suptitle.get_text()
    assert "sim vs proxy," in title and "MuJoCo" not in title
    mujoco = steps[steps["plant"] == "sim"].assign(plant="mujoco")
    title = force_error_figure(pd.concat([steps, mujoco]))._suptitle.get_text()
    assert "sim vs proxy vs MuJoCo," in title


def test_a_short_runs_fig5_line_follows_its_episodes():
    curve = curve_frame().head(12)
    fig = training_figure(curve)
    line = fig.axes[0].lines[1]  # the RL rolling mean
    values = np.asarray(line.get_ydata(), float)
    assert np.isfinite(values).all() and np.ptp(values) > 0.0
    assert "rolling mean over 3 episodes" in fig._suptitle.get_text()


def test_no_negative_zero_degrees_in_a_title():
    from pushctl.report.plan_figure import _degrees as plan_degrees
    from pushctl.report.trace_figure import _degrees

    assert _degrees(-1e-6, 2) == "0.00" and _degrees(np.radians(-1.5), 2) == "-1.50"
    assert plan_degrees(-1e-6) == "0.0" and plan_degrees(np.radians(30.0)) == "+30.0"


def test_the_recorded_pushes_figures_label_their_axes_and_every_line():
    from pushctl.realdata.figures import example_pushes_figure

    square = np.array([(0.04, -0.04), (0.04, 0.04), (-0.04, 0.04), (-0.04, -0.04)])
    pushes = pd.DataFrame(
        [{"push_id": f"p{i}", "shape": "square", "x0": 0.0, "y0": 0.0, "theta0": 0.0,
          "x1": 0.01, "y1": 0.0, "theta1": 0.1, "tip_x0": -0.05, "tip_y0": 0.0,
          "tip_x1": -0.03, "tip_y1": 0.0} for i in range(2)]
    )  # fmt: skip
    ends = np.array([[0.01, 0.0, 0.1], [0.01, 0.0, 0.1]])
    fig = example_pushes_figure(pushes, {"square": square}, ends, ends, count=2)
    assert all(ax.get_xlabel() == "x [mm]" and ax.get_ylabel() == "y [mm]" for ax in fig.axes)
    labels = [text.get_text() for legend in fig.legends for text in legend.get_texts()]
    assert labels == ["start", "recorded end", "ours", "Zhou", "pusher tip"]


def test_a_line_hidden_under_another_is_named():
    from pushctl.cli.report_steps import hidden_lines

    steps = steps_frame()
    assert hidden_lines(steps) is None
    feedback = steps[steps["controller"] == "feedback"]
    same = pd.concat([steps[steps["controller"] != "rl"], feedback.assign(controller="rl")])
    note = hidden_lines(same)
    assert note is not None and "RL-assisted's lie exactly on feedback (PD + PI)'s" in note
