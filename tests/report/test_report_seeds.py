"""Several training seeds in the report (pushctl.report.seeds), on the synthetic trials of
test_report with the ``rl`` rows repeated per seed and scaled by a known factor per seed:
RL cells are the mean over the trials of the per-trial mean over seeds with the interval
over the trials (as every other column's), the spread across seeds in ``_seed_sd``, the
ratios' ± across seeds (hand computed); PD-only and feedback columns are unchanged, each
seed's own ratios are listed, RL − feedback is paired over the trials, and with one seed
(or none named) the tables are today's to the byte."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy import stats
from synthetic_results import trials_frame, write_results
from typer.testing import CliRunner

from pushctl.cli import app
from pushctl.report.inputs import ResultsFileError, read_report_inputs
from pushctl.report.markdown import tables_markdown
from pushctl.report.seeds import SEED_RATIOS, policy_seeds, seed_tables
from pushctl.report.tables import table3, table4

SCALES = {0: 0.8, 1: 1.0, 2: 1.3}
"""Seed → factor on its rl metrics (test_report's rl metric is (trial + 1) × the plant's
factor; PD-only's is twice that, feedback's 1.25 times)."""
T_2 = float(stats.t.ppf(0.975, 2))
T_3 = float(stats.t.ppf(0.975, 3))
MEAN_SCALE = float(np.mean(list(SCALES.values())))  # the per-trial mean over seeds' factor


def seeded_frame(scales: dict[int, float] = SCALES) -> pd.DataFrame:
    """test_report's trials with one set of rl rows per seed, its metrics × the seed's
    factor, and a ``policy_seed`` column (empty on pd and feedback rows)."""
    base = trials_frame()
    others = base[base["controller"] != "rl"].assign(policy_seed=math.nan)
    metrics = ["translation_error_pct", "angle_error_pct", "force_error", "torque_error"]
    frames = [others]
    for seed, scale in scales.items():
        rl = base[base["controller"] == "rl"].copy()
        rl[metrics] = rl[metrics] * scale
        frames.append(rl.assign(policy_seed=float(seed)))
    return pd.concat(frames, ignore_index=True)


def _cell(frame: pd.DataFrame, obj: str, profile: str, column: str) -> float:
    row = frame[(frame["object"] == obj) & (frame["profile"] == profile)]
    assert len(row) == 1
    return float(row[column].iloc[0])


def _ci(values: list[float]) -> float:
    return T_2 * float(np.std(values, ddof=1)) / math.sqrt(len(values))


def _trial_ci(values: np.ndarray) -> float:
    """The 95 % half-width over 4 trials."""
    return T_3 * float(np.std(values, ddof=1)) / 2.0


def test_rl_cells_have_the_interval_over_trials_and_the_seed_spread_apart():
    """wedge/chirp, sim: seed s pushes trial i to (i + 1) × scale_s %; the per-trial mean
    over seeds is (i + 1) × 1.033 %, whose mean and interval over the 4 trials are the RL
    cell, as PD-only's and feedback's are theirs; the seeds' own cell means (2.5 × scale_s)
    give the ``_seed_sd`` column."""
    frame = seeded_frame()
    seeds = seed_tables(frame)
    assert seeds.seeds == (0, 1, 2) and seeds.several
    three = seeds.table3.values
    per_trial = np.arange(1.0, 5.0) * MEAN_SCALE
    assert _cell(three, "wedge", "chirp", "translation_error_rl") == pytest.approx(
        per_trial.mean(), rel=1e-12
    )
    assert _cell(three, "wedge", "chirp", "translation_error_rl_ci95") == pytest.approx(
        _trial_ci(per_trial), rel=1e-12
    )
    per_seed = [2.5 * m for m in SCALES.values()]  # wedge/chirp's sim rl mean per seed [%]
    assert _cell(three, "wedge", "chirp", "translation_error_rl_seed_sd") == pytest.approx(
        np.std(per_seed, ddof=1), rel=1e-12
    )
    # feedback's interval is over the same 4 trials, under the same kind of name
    feedback = np.arange(1.0, 5.0) * 1.25
    assert _cell(three, "wedge", "chirp", "translation_error_feedback_ci95") == pytest.approx(
        _trial_ci(feedback), rel=1e-12
    )
    assert not any(c.endswith("_seed_sd") and "_rl" not in c for c in three.columns)
    # PD-only and feedback (run once per trial) are the single-seed table's
    plain = table3(frame).values
    for column in ("translation_error_pd", "angle_error_feedback", "angle_error_pd_ci95"):
        np.testing.assert_array_equal(three[column].to_numpy(), plain[column].to_numpy())
    # Table IV too: the proxy's rl force error [N], 1.5 × sim
    four = seeds.table4.values
    proxy = 1.5e-3 * np.arange(1.0, 5.0) * MEAN_SCALE
    assert _cell(four, "cube", "trapezoid", "force_error_rl_proxy") == pytest.approx(
        proxy.mean(), rel=1e-12
    )
    assert _cell(four, "cube", "trapezoid", "force_error_rl_proxy_ci95") == pytest.approx(
        _trial_ci(proxy), rel=1e-12
    )
    assert _cell(four, "cube", "trapezoid", "force_error_rl_proxy_seed_sd") == pytest.approx(
        np.std([1.5 * 2.5e-3 * m for m in SCALES.values()], ddof=1), rel=1e-12
    )
    # counts: the trials behind the rl mean, as for PD-only
    assert _cell(seeds.table3.counts, "wedge", "chirp", "translation_error_rl") == 4


def test_rl_minus_feedback_is_paired_over_the_trials():
    """Trial i: RL's mean over seeds (i + 1) × 1.033, feedback's (i + 1) × 1.25 (sim,
    wedge/trapezoid): the difference (i + 1) × (−0.217) over 4 trials; the straight push's
    NaN angle (PD-only's only) does not touch RL − feedback."""
    paired = seed_tables(seeded_frame()).paired
    row = paired[
        (paired["object"] == "wedge")
        & (paired["profile"] == "trapezoid")
        & (paired["plant"] == "sim")
    ]
    assert len(row) == 1
    diff = np.arange(1.0, 5.0) * (MEAN_SCALE - 1.25)
    assert float(row["translation_error_pct_diff"].iloc[0]) == pytest.approx(diff.mean())
    assert float(row["translation_error_pct_diff_ci95"].iloc[0]) == pytest.approx(
        _trial_ci(diff), rel=1e-12
    )
    assert float(row["angle_error_pct_diff"].iloc[0]) == pytest.approx(diff.mean() / 10)
    assert int(row["angle_error_pct_diff_n"].iloc[0]) == 4
    assert set(paired["plant"]) == {"sim", "proxy"} and len(paired) == 12


def test_each_seed_s_own_ratios_and_their_interval():
    seeds = seed_tables(seeded_frame())
    per_seed = seeds.per_seed
    assert list(per_seed.columns) == [
        "object",
        "profile",
        "policy_seed",
        "translation_error_rl",
        "angle_error_rl",
        *(name for name, _, _ in SEED_RATIOS),
    ]
    assert len(per_seed) == 6 * 3
    cell = per_seed[(per_seed["object"] == "wedge") & (per_seed["profile"] == "trapezoid")]
    assert list(cell["policy_seed"]) == [0, 1, 2]
    scales = np.array(list(SCALES.values()))
    np.testing.assert_allclose(cell["translation_rl_pd"], scales / 2.0, rtol=1e-12)
    np.testing.assert_allclose(cell["angle_rl_feedback"], scales / 1.25, rtol=1e-12)
    # the straight push's NaN PD angle is left out: PD's angle mean is (2+3+4)/3 × 2 / 10
    straight = per_seed[(per_seed["object"] == "cube") & (per_seed["profile"] == "constant")]
    np.testing.assert_allclose(straight["angle_rl_pd"], 0.25 * scales / 0.6, rtol=1e-12)
    key = ("wedge", "trapezoid", "translation_error_rl", "translation_error_pd")
    assert seeds.ratio_ci[key] == pytest.approx(_ci(list(scales / 2.0)), rel=1e-12)
    key = ("cube", "chirp", "torque_error_rl_sim", "torque_error_feedback_sim")
    assert seeds.ratio_ci[key] == pytest.approx(_ci(list(scales / 1.25)), rel=1e-12)


def test_the_markdown_shows_ratios_across_seeds_and_each_seed_s_table():
    frame = seeded_frame()
    seeds = seed_tables(frame)
    text = tables_markdown(seeds.table3, seeds.table4, "# made by: x", ["in"], seeds)
    assert "the mean over the 3 training seeds (0, 1, 2)" in text
    assert "interval over the trials" in text and "`_seed_sd`" in text
    diff = 2.5 * (MEAN_SCALE - 1.25)  # wedge/chirp sim, RL − feedback [pp]
    ci = _trial_ci(np.arange(1.0, 5.0) * (MEAN_SCALE - 1.25))
    assert f"| wedge | chirp | sim | 4 | {diff:+.4f} ± {ci:.4f} (below 0) |" in text
    ratio = 1.0333333333333334 / 2.0
    ci = _ci([m / 2.0 for m in SCALES.values()])
    assert f"| wedge | chirp | {ratio:.2f} ± {ci:.2g} |" in text
    assert "| object | profile | seed | translation_rl_pd |" in text
    assert f"| wedge | chirp | 2 | {1.3 / 2.0:.2f} | {1.3 / 1.25:.2f} |" in text


@pytest.mark.parametrize("named", ["one seed", "no column"])
def test_with_one_seed_the_tables_are_today_s(named: str):
    frame = seeded_frame({4: 1.0})
    if named == "no column":
        frame = frame.drop(columns="policy_seed")
    plain = trials_frame()
    seeds = seed_tables(frame)
    assert not seeds.several and seeds.ratio_ci == {}
    assert seeds.seeds == () and policy_seeds(frame) == ([4] if named == "one seed" else [])
    pd.testing.assert_frame_equal(seeds.table3.values, table3(plain).values)
    pd.testing.assert_frame_equal(seeds.table4.values, table4(plain).values)
    today = tables_markdown(
        table3(plain), table4(plain), "# made by: x", ["in"], seed_tables(plain)
    )
    assert tables_markdown(seeds.table3, seeds.table4, "# made by: x", ["in"], seeds) == today
    assert "RL-assisted − feedback, paired over the trials" in today
    assert len(seeds.per_seed) == 6  # the seed's own ratios are still available


def _write_seeded(root: Path, frame: pd.DataFrame) -> Path:
    results = write_results(root)
    frame.to_csv(results / "evaluation" / "trials.csv", index=False)
    return results


def test_inputs_accept_one_rl_row_per_trial_and_seed_but_not_two(tmp_path: Path):
    frame = seeded_frame()
    inputs = read_report_inputs(_write_seeded(tmp_path / "ok", frame))
    assert policy_seeds(inputs.trials.frame) == [0, 1, 2]
    twice = pd.concat([frame, frame[frame["policy_seed"] == 1]], ignore_index=True)
    with pytest.raises(ResultsFileError, match=r"repeats \(.*policy_seed=1.0\)"):
        read_report_inputs(_write_seeded(tmp_path / "twice", twice))


def test_the_report_writes_the_per_seed_csv_with_several_seeds(tmp_path: Path):
    results = _write_seeded(tmp_path / "results", seeded_frame())
    out = tmp_path / "out"
    result = CliRunner().invoke(app, ["report", "--in", str(results), "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert f"{out / 'table3_seeds.csv'}" in result.output.replace("\n", "")
    text = (out / "table3_seeds.csv").read_text()
    assert text.startswith("# made by: pushctl report")
    written = pd.read_csv(out / "table3_seeds.csv", comment="#")
    assert list(written["policy_seed"]) == [0, 1, 2] * 6
    np.testing.assert_allclose(written["translation_rl_pd"], np.tile([0.4, 0.5, 0.65], 6))
    assert "Each training seed's own ratios" in (out / "tables.md").read_text()


def test_a_metric_read_as_text_is_averaged_over_the_seeds_too():
    """The report's reader may leave a column as text (``force_error_landed`` in the
    shipped trials): RL's per-trial mean over the seeds must still be its mean."""
    frame = seeded_frame()
    text = frame.assign(force_error=frame["force_error"].astype(str))
    want = seed_tables(frame).table4.values
    got = seed_tables(text).table4.values
    for column in ("force_error_rl_sim", "force_error_rl_sim_ci95", "force_error_rl_proxy"):
        np.testing.assert_allclose(got[column], want[column], rtol=1e-12)
