"""Tests of pushctl.report's tables, inputs and figures, on small synthetic results CSVs with
known means: the table values and confidence intervals against hand computations, the
column order, NaN-aware means, the paper's values in tables.md, the figures' panels, and
one-line errors for every kind of bad input."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy import stats
from synthetic_results import (
    CI_234,
    CI_1234,
    EPISODES,
    OBJECTS,
    PD_EVERY,
    PROFILES,
    TRIALS,
    TRIALS_MADE_BY,
    curve_frame,
    sign,
    steps_frame,
    trials_frame,
    write_results,
)

from pushctl.report import paper_values
from pushctl.report.figures import (
    force_error_figure,
    rolling_mean,
    tracking_figure,
    training_figure,
)
from pushctl.report.inputs import (
    CURVE_SPEC,
    TRIALS_SPEC,
    ResultsFileError,
    read_report_inputs,
    read_results_csv,
)
from pushctl.report.markdown import tables_markdown
from pushctl.report.tables import (
    TABLE3_COLUMNS,
    TABLE4_COLUMNS,
    ci95_halfwidth,
    table3,
    table4,
)


@pytest.fixture
def results(tmp_path: Path) -> Path:
    return write_results(tmp_path / "results")


def _cell(frame: pd.DataFrame, obj: str, profile: str, column: str) -> float:
    row = frame[(frame["object"] == obj) & (frame["profile"] == profile)]
    assert len(row) == 1
    return float(row[column].iloc[0])


# ---------------------------------------------------------------- tables


def test_table3_columns_values_and_ci_match_a_hand_computation():
    result = table3(trials_frame())
    values = list(TABLE3_COLUMNS)
    assert list(result.values.columns) == ["object", "profile", *values] + [
        f"{c}_ci95" for c in values
    ]
    assert list(zip(result.values["object"], result.values["profile"], strict=True)) == [
        (o, p) for o in OBJECTS for p in PROFILES
    ]
    frame = result.values
    # sim plant only: PD factor 2, RL factor 1 (the proxy's 1.5 × must not leak in)
    assert _cell(frame, "wedge", "chirp", "translation_error_pd") == pytest.approx(5.0)
    assert _cell(frame, "wedge", "chirp", "translation_error_rl") == pytest.approx(2.5)
    assert _cell(frame, "wedge", "chirp", "translation_error_feedback") == pytest.approx(3.125)
    ci = _cell(frame, "wedge", "chirp", "translation_error_pd_ci95")
    assert ci == pytest.approx(2.0 * CI_1234, rel=1e-10)
    assert _cell(frame, "cube", "trapezoid", "angle_error_rl_ci95") == pytest.approx(
        0.1 * CI_1234, rel=1e-10
    )


def test_nan_angle_errors_are_left_out_of_the_mean_and_its_count():
    result = table3(trials_frame())
    # cube/constant/pd angle errors: NaN, 0.4, 0.6, 0.8 → mean 0.6 over n = 3
    assert _cell(result.values, "cube", "constant", "angle_error_pd") == pytest.approx(0.6)
    ci = _cell(result.values, "cube", "constant", "angle_error_pd_ci95")
    assert ci == pytest.approx(0.2 * CI_234, rel=1e-10)
    assert _cell(result.counts, "cube", "constant", "angle_error_pd") == 3
    assert _cell(result.counts, "cube", "constant", "translation_error_pd") == TRIALS


def test_table4_columns_and_plants():
    result = table4(trials_frame())
    values = list(TABLE4_COLUMNS)
    assert values[:6] == [
        "force_error_pd_sim",
        "force_error_pd_proxy",
        "force_error_feedback_sim",
        "force_error_feedback_proxy",
        "force_error_rl_sim",
        "force_error_rl_proxy",
    ]
    assert list(result.values.columns) == ["object", "profile", *values] + [
        f"{c}_ci95" for c in values
    ]
    frame = result.values
    assert _cell(frame, "cube", "chirp", "force_error_pd_proxy") == pytest.approx(7.5e-3)
    assert _cell(frame, "cube", "chirp", "torque_error_rl_sim") == pytest.approx(2.5e-5)
    ci = _cell(frame, "wedge", "constant", "torque_error_rl_proxy_ci95")
    assert ci == pytest.approx(1.5e-5 * CI_1234, rel=1e-10)


def test_a_missing_plant_gives_nan_and_a_zero_count():
    trials = trials_frame()
    result = table4(trials[trials["plant"] == "sim"])
    assert math.isnan(_cell(result.values, "cube", "constant", "force_error_pd_proxy"))
    assert _cell(result.counts, "cube", "constant", "force_error_pd_proxy") == 0
    assert _cell(result.values, "cube", "constant", "force_error_pd_sim") == pytest.approx(5e-3)


def test_rows_follow_the_papers_order_whatever_the_files():
    shuffled = trials_frame().sample(frac=1.0, random_state=3)
    frame = table3(shuffled).values
    cells = list(zip(frame["object"], frame["profile"], strict=True))
    assert cells == [(o, p) for o in OBJECTS for p in PROFILES]


@pytest.mark.parametrize("n", [2, 3, 10, 50])
def test_ci95_is_half_the_scipy_t_interval(n):
    values = np.random.default_rng(n).normal(3.0, 2.0, n)
    low, high = stats.t.interval(0.95, n - 1, loc=values.mean(), scale=stats.sem(values))
    assert ci95_halfwidth(values) == pytest.approx(0.5 * (high - low), rel=1e-12)


def test_ci95_is_nan_below_two_finite_values():
    assert math.isnan(ci95_halfwidth(np.array([1.0])))
    assert math.isnan(ci95_halfwidth(np.array([np.nan, 2.0, np.inf])))


# ---------------------------------------------------------------- paper values, markdown


def test_paper_values_are_in_si_and_cover_every_cell():
    for table, columns in (
        (paper_values.TABLE3, TABLE3_COLUMNS),
        (paper_values.TABLE4, TABLE4_COLUMNS),
    ):
        assert set(table) == {(o, p) for o in OBJECTS for p in PROFILES}
        # every column but our force error against the plant's needs and the feedback
        # baseline's, which the paper lacks
        ours_only = {c for c in columns if c.startswith("force_error_") and "plan" not in c}
        ours_only |= {c for c in columns if "feedback" in c}
        for row in table.values():
            assert set(row) == set(columns) - ours_only
    assert paper_values.TABLE3[("wedge", "chirp")]["translation_error_pd"] == 29.6
    cube = paper_values.TABLE4[("cube", "constant")]
    assert cube["force_error_plan_pd_sim"] == pytest.approx(0.171)  # printed 1.71 × 10⁻¹ N
    assert cube["torque_error_rl_proxy"] == pytest.approx(2.52e-3)  # printed 2.52 × 10⁻³ N·m


def test_markdown_shows_ours_beside_the_papers_values():
    trials = trials_frame()
    text = tables_markdown(
        table3(trials), table4(trials), "# made by: pushctl report", ["trials.csv [x]"]
    )
    lines = text.splitlines()
    assert lines[0] == "<!-- made by: pushctl report -->"
    assert "- trials.csv [x]" in lines
    (cube_constant,) = [
        line for line in lines if line.startswith("| cube | constant | 4 / 4 / 4 / 3 / 4 / 4 |")
    ]
    # n differs (3 angle values for PD), ours ± CI then the paper's 22.3; feedback without a
    # paper column; RL and the paper's 4.0
    assert f"| 5 ± {2 * CI_1234:.2g} | 22.3 | 3.12 ± {1.25 * CI_1234:.2g} | 2.5 ±" in cube_constant
    assert "| 4.0 |" in cube_constant
    assert "| 256 |" in text  # wedge trapezoid PD real force, 2.56 × 10⁻¹ N in mN
    assert "| 8.33 |" in text  # wedge chirp PD real torque [mN·m]
    # RL/PD ratio: ours 0.5 everywhere, the paper's translation on cube constant 4.0/22.3;
    # RL/feedback: ours 0.8, no paper column; angle RL/PD 0.25 / 0.6 (PD's NaN left out)
    assert "| cube | constant | 0.50 | 0.18 | 0.80 | 0.42 |" in text
    assert "real robot" in text and "10⁻¹ N" in text


def test_table4_shows_force_error_against_the_plan_beside_the_paper_and_the_plant_s_alone():
    trials = trials_frame()
    trials["force_error_plan"] = 3.0 * trials["force_error"]
    text = tables_markdown(table3(trials), table4(trials), "# made by: x", ["trials.csv"])
    plan_part = text.split("against the nominal plan [mN]")[1].split("against what the plant")[0]
    plant_part = text.split("against what the plant needed [mN]")[1].split("where they landed")[0]
    landed_part = text.split("where they landed [mN]")[1].split("Torque error")[0]
    # cube chirp PD sim: plan 3 × 5 mN beside the paper's 205 mN; the plant's 5 mN alone
    assert "| cube | chirp | 4 | 15 ± " in plan_part and "| 205 |" in plan_part
    (row,) = [line for line in plant_part.splitlines() if line.startswith("| cube | chirp |")]
    assert row.startswith("| cube | chirp | 4 | 5 ± ") and row.count("|") == 10  # no paper
    (row,) = [line for line in landed_part.splitlines() if line.startswith("| cube | chirp |")]
    assert row.startswith("| cube | chirp | 4 | 2.5 ± ") and row.count("|") == 10
    assert "| force vs plan sim RL/PD (ours) | paper |" in text
    assert "| force vs landed sim RL/PD (ours) | paper |" in text
    # an older trials.csv without the column still makes the table (NaN: "–")
    older = table4(trials_frame().drop(columns="force_error_landed"))
    assert np.isnan(older.values["force_error_landed_pd_sim"]).all()
    assert np.isnan(older.values["force_error_plan_pd_sim"]).all()
    assert (older.counts["force_error_plan_pd_sim"] == 0).all()


# ---------------------------------------------------------------- inputs


def test_inputs_are_read_with_their_provenance(results):
    inputs = read_report_inputs(results)
    assert inputs.trials.made_by == TRIALS_MADE_BY[1:].strip()
    assert inputs.steps.made_by is None
    assert inputs.curve.frame["pd_force_n_error"].notna().sum() == EPISODES // PD_EVERY
    assert inputs.trials.frame["translation_error_pct"].dtype == float


def _rewrite(path: Path, edit) -> None:
    """Edit the lines of ``path`` (its digest line left out) and sign it again: what is
    checked is what follows the digest."""
    lines = [line for line in path.read_text().splitlines() if not line.startswith("# sha256")]
    path.write_text("\n".join(edit(lines)) + "\n")
    sign(path)


@pytest.mark.parametrize(
    ("edit", "fragment"),
    [
        (lambda lines: [], "empty file"),
        (lambda lines: lines[:2], "no data rows"),
        (lambda lines: [lines[1].replace("force_error", "force_err"), *lines[2:]], "force_error"),
        (lambda lines: [*lines[:3], lines[3].replace(",sim,", ",real,"), *lines[4:]], "real"),
        (
            lambda lines: [*lines[:2], lines[2].replace(",100,", ",100,x"), *lines[3:]],
            "not a number",
        ),
        (lambda lines: [*lines, lines[-1]], "repeats"),
        (lambda lines: [*lines[:2], lines[2] + ",1,2,3", *lines[3:]], "well-formed"),
    ],
    ids=["empty", "header-only", "missing-column", "bad-plant", "garbage", "duplicate", "ragged"],
)
def test_bad_trials_files_raise_one_line_naming_the_file(results, edit, fragment):
    path = results / "evaluation" / "trials.csv"
    _rewrite(path, edit)
    with pytest.raises(ResultsFileError) as caught:
        read_report_inputs(results)
    message = str(caught.value)
    assert str(path) in message and fragment in message
    assert "\n" not in message


def test_a_non_numeric_metric_is_named_with_its_row(results):
    path = results / "evaluation" / "trials.csv"
    frame = trials_frame().astype({"force_error": object})
    frame.loc[5, "force_error"] = "n/a"
    frame.to_csv(path, index=False)
    with pytest.raises(ResultsFileError, match=r"column force_error, data row 6: 'n/a'"):
        read_results_csv(path, TRIALS_SPEC)


def test_empty_pd_cells_are_allowed_but_empty_rl_cells_are_not(results):
    path = results / "training" / "curve.csv"
    assert read_results_csv(path, CURVE_SPEC).frame["pd_torque_error"].isna().any()
    frame = curve_frame()
    frame.loc[3, "rl_torque_error"] = np.nan
    frame.to_csv(path, index=False)
    with pytest.raises(ResultsFileError, match="rl_torque_error, data row 4: '' is an empty"):
        read_results_csv(path, CURVE_SPEC)


@pytest.mark.parametrize("missing", ["", "evaluation/trials.csv", "evaluation/steps.csv"])
def test_missing_directory_or_file_is_named(tmp_path, missing):
    root = write_results(tmp_path / "r") if missing else tmp_path / "nowhere"
    if missing:
        (root / missing).unlink()
    with pytest.raises(ResultsFileError, match="no such"):
        read_report_inputs(root)


# ---------------------------------------------------------------- figures


def test_rolling_mean_spans_the_same_episodes_for_sparse_series():
    episode = np.arange(0, 400, 4.0)
    values = np.where(episode < 200, 1.0, 3.0)
    smooth = rolling_mean(episode, values, window=40)  # 10 points of a 4-episode series
    assert smooth[:20] == pytest.approx(1.0) and smooth[-20:] == pytest.approx(3.0)
    middle = smooth[np.searchsorted(episode, 200)]
    assert 1.5 < middle < 2.5  # the step is blurred over about 40 episodes, no more
    assert smooth[np.searchsorted(episode, 224)] == pytest.approx(3.0)


def test_training_figure_draws_pd_only_where_it_ran():
    fig = training_figure(curve_frame(), window=8)
    axes = fig.get_axes()
    assert len(axes) == 3
    assert [ax.get_ylabel().split(" [")[-1] for ax in axes] == ["mN]", "mN]", "mN·m]"]
    assert axes[-1].get_xlabel() == "training episode"
    lines = axes[0].get_lines()
    pd_points = [line for line in lines if len(line.get_xdata()) == EPISODES // PD_EVERY]
    assert pd_points and all(np.all(np.asarray(p.get_xdata()) % PD_EVERY == 0) for p in pd_points)
    # RL's raw points carry the curve's values in mN
    rl_raw = [line for line in lines if line.get_linestyle() == "None"][0]
    assert np.asarray(rl_raw.get_ydata())[0] == pytest.approx(1e3 * 2e-2)
    assert "Fig. 5" in fig.get_suptitle()


def test_tracking_figure_has_a_column_per_profile_and_draws_the_sim_plant():
    steps = steps_frame()
    fig = tracking_figure(steps)
    axes = fig.get_axes()
    assert len(axes) == 4 * len(PROFILES)
    assert [axes[c].get_title() for c in range(3)] == [f"{p} profile" for p in PROFILES]
    error_panel = axes[len(PROFILES)]  # translation error, constant profile
    drawn = {float(np.asarray(line.get_ydata())[-1]) for line in error_panel.get_lines()}
    assert drawn == {2.0, 1.25, 1.0}  # sim PD, feedback and RL lags; no proxy line drawn
    legend = [t.get_text() for t in fig.legends[0].get_texts()]
    assert legend == ["desired", "PD-only", "feedback (PD + PI)", "RL-assisted", "cube", "wedge"]


def test_tracking_figure_of_one_cell_and_proxy_only():
    steps = steps_frame()
    one = steps[(steps["object"] == "wedge") & (steps["profile"] == "chirp")]
    fig = tracking_figure(one[one["plant"] == "proxy"])
    assert len(fig.get_axes()) == 4
    assert "proxy plant (no sim rows)" in " ".join(fig.get_suptitle().split())  # wrapped


def test_force_error_figure_shows_sim_and_proxy_for_both_controllers():
    fig = force_error_figure(steps_frame())
    axes = fig.get_axes()
    assert len(axes) == 2 * len(OBJECTS) * len(PROFILES)
    first = axes[0]
    assert first.get_ylabel().startswith("cube\nforce error")
    assert first.get_xlim()[1] >= 1.0
    bold = [line for line in first.get_lines() if line.get_linewidth() > 1.0]
    levels = sorted(float(np.nanmax(line.get_ydata())) for line in bold)
    assert levels == pytest.approx([1.0, 1.5, 2.0, 3.0])  # RL sim, RL proxy, PD sim, PD proxy [mN]
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert "PD-only, proxy" in labels and "RL-assisted, sim" in labels
