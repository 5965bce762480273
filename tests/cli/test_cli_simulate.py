"""``pushctl simulate`` and ``pushctl tune-pd``: the trace CSV and figure, seeds and plant
overrides, the gains file with its search record, and one-line errors with no file written.

Every run passes ``--gains`` and ``--out`` into ``tmp_path``: nothing here reads or writes
``pushctl/defaults/pd_gains.toml``.
"""

import itertools
import math
import re

import pandas as pd
import pytest
from typer.testing import CliRunner

from pushctl.cli import app
from pushctl.control.gains import PDGains, gains_toml, load_gains
from pushctl.evaluation.tune_pd import GRID
from pushctl.files.toml import tomllib

runner = CliRunner()

FIRST_COLUMNS = (
    "t,obj_x,obj_y,obj_theta,des_x,des_y,des_theta,lambda_n_1,lambda_t_1,lambda_n_2,"
    "lambda_t_2,force_n_des_1,force_t_des_1,force_n_des_2,force_t_des_2,tau_z,tau_z_des"
).split(",")

PLANT = re.compile(r"plant\s*│\s*μ_g (\S+), μ_c (\S+), object (\S+) kg")
"""The printed plant row (not the "planned with" row: that has no "│" after "plant")."""

TUNE_BUDGET = (
    "--objects", "cube", "--profiles", "chirp", "--per-case", "1", "--duration", "1",
    "--max-rounds", "0",
)  # fmt: skip


@pytest.fixture
def gains(tmp_path):
    path = tmp_path / "gains.toml"
    path.write_text(gains_toml(PDGains(kp=300, kv=200, kx_linear=50, kx_angular=50), "test gains"))
    return path


def _simulate(gains, *args):
    return runner.invoke(app, ["simulate", "--gains", str(gains), "--duration", "2", *args])


def _plant(output):
    match = PLANT.search(output)
    assert match is not None, output
    return match.groups()


def _assert_one_line_error(result, fragment):
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith("error:") and fragment in lines[0], result.stderr


# --- pushctl simulate: what it writes -------------------------------------------------------


def test_simulate_writes_trace_csv_figure_and_metrics(tmp_path, gains):
    out, plot = tmp_path / "t.csv", tmp_path / "t.png"
    result = _simulate(
        gains, "--object", "cube", "--profile", "chirp", "--goal", "0.55,0.02,15",
        "--out", str(out), "--plot", str(plot),
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    assert "translation error" in result.output and "force error" in result.output
    assert "angle error" in result.output
    first_line = out.read_text().splitlines()[0]
    assert first_line.startswith("# made by: pushctl simulate")
    assert "commit" in first_line and "no seed" in first_line
    assert "--out" not in first_line and "--plot" not in first_line  # where, not what
    frame = pd.read_csv(out, comment="#")
    assert len(frame) == 201  # duration / h + 1
    assert list(frame.columns[: len(FIRST_COLUMNS)]) == FIRST_COLUMNS
    assert frame.t.iloc[0] == 0.0
    assert frame.t.iloc[-1] == pytest.approx(2.0)
    last = frame.iloc[-1]
    assert (last.des_x, last.des_y) == pytest.approx((0.55, 0.02), abs=1e-9)
    assert last.des_theta == pytest.approx(math.radians(15.0), abs=1e-9)
    assert frame[FIRST_COLUMNS].notna().all().all()
    assert plot.stat().st_size > 0 and plot.read_bytes()[:4] == b"\x89PNG"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["gains.toml", "t.csv", "t.png"]


def test_seed_without_goal_is_reproducible_to_the_byte(tmp_path, gains):
    path = tmp_path / "a.csv"  # one path: the provenance line records --out too
    result = _simulate(gains, "--scenario", "3", "--out", str(path))
    assert result.exit_code == 0, result.output
    assert "3 (evaluation stream" in result.output
    assert _plant(result.output)[:2] == ("0.300", "0.400")
    assert "seed 3" in path.read_text().splitlines()[0]
    first = path.read_bytes()
    # the second run overwrites its own file: --force (which the provenance does not record)
    assert _simulate(gains, "--scenario", "3", "--out", str(path), "--force").exit_code == 0
    assert path.read_bytes() == first


def test_randomize_draws_the_plant_but_keeps_the_seeds_goal(tmp_path, gains):
    nominal, randomized = tmp_path / "nominal.csv", tmp_path / "randomized.csv"
    assert _simulate(gains, "--scenario", "3", "--out", str(nominal)).exit_code == 0
    result = _simulate(gains, "--scenario", "3", "--randomize", "--out", str(randomized))
    assert result.exit_code == 0, result.output
    mu_ground, mu_contact, _ = _plant(result.output)
    assert mu_ground != "0.300" and mu_contact != "0.400"
    assert "planned with │ μ_g 0.300, μ_c 0.400" in result.output
    assert "unknowns     │ placement" in result.output  # the drawn plant unknowns
    assert "unknowns" not in _simulate(gains, "--scenario", "3").output  # none without --randomize
    # Different plant, different trace (compare the data rows, not the provenance line).
    assert nominal.read_text().splitlines()[1:] != randomized.read_text().splitlines()[1:]
    goal = ["des_x", "des_y", "des_theta"]
    a = pd.read_csv(nominal, comment="#")[goal].iloc[-1]
    b = pd.read_csv(randomized, comment="#")[goal].iloc[-1]
    assert list(a) == list(b)


def test_plant_overrides_show_in_the_plant_line(gains):
    result = _simulate(
        gains, "--goal", "0.55,0.02,15",
        "--mu-contact", "0.3", "--mu-ground", "0.35", "--object-mass", "0.4",
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    assert _plant(result.output) == ("0.350", "0.300", "0.400")
    assert "planned with │ μ_g 0.300, μ_c 0.400, object 0.300 kg" in result.output


# --- pushctl simulate: bad input ----------------------------------------------------------


GOAL = ("--goal", "0.55,0.02,15")


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        ([], "give a goal"),
        (["--goal", "0.55,0.02,15", "--randomize"], "--randomize"),
        (["--randomize"], "give a goal"),
        ([*GOAL, "--controller", "rl", "--policy", "none.pt"], "no policy file at none.pt"),
        ([*GOAL, "--controller", "xyz"], "unknown controller 'xyz'; accepted: pd, feedback, rl"),
        ([*GOAL, "--profile", "zigzag"], "constant, trapezoid, chirp"),
        ([*GOAL, "--object", "sphere"], "cube, wedge"),
        (["--scenario", "3", "--object", "sphere"], "cube, wedge"),
        (["--goal", "1,2"], "x,y,theta_deg"),
        (["--goal", "nan,0,0"], "finite"),
        (["--goal", "0.30,0,0"], "behind the pushed face"),
        (["--goal", "0.95,0,0"], "out of reach"),
        ([*GOAL, "--mu-contact", "-1"], "mu_contact"),
        ([*GOAL, "--object-mass", "0"], "object_mass"),
        (["--scenario", "-1"], "--scenario must be an integer >= 0"),
        ([*GOAL, "--arm", "ur5"], "kinova-gen2-7dof"),
        ([*GOAL, "--duration", "0"], "duration must be a positive"),
    ],
)
def test_bad_input_is_one_line_exit_2_and_no_file(tmp_path, gains, args, fragment):
    out, plot = tmp_path / "t.csv", tmp_path / "t.png"
    result = _simulate(gains, *args, "--out", str(out), "--plot", str(plot))
    _assert_one_line_error(result, fragment)
    assert not out.exists() and not plot.exists()
    assert [p.name for p in tmp_path.iterdir()] == ["gains.toml"]


def test_missing_gains_file_is_one_line(tmp_path):
    out = tmp_path / "t.csv"
    result = _simulate(tmp_path / "nope.toml", *GOAL, "--out", str(out))
    _assert_one_line_error(result, "nope.toml does not exist")
    assert list(tmp_path.iterdir()) == []


def test_corrupt_gains_file_is_one_line(tmp_path):
    corrupt = tmp_path / "corrupt.toml"
    corrupt.write_text("[pd\nkp = \n")
    out = tmp_path / "t.csv"
    result = _simulate(corrupt, *GOAL, "--out", str(out))
    _assert_one_line_error(result, "cannot read gains file")
    assert "corrupt.toml" in result.stderr
    assert [p.name for p in tmp_path.iterdir()] == ["corrupt.toml"]


@pytest.mark.parametrize(
    ("option", "name", "fragment"),
    [
        ("--out", "t.txt", "--out must end in .csv"),
        ("--out", "missing/t.csv", "does not exist"),
        ("--plot", "t.gif", "--plot must end in .png"),
    ],
)
def test_bad_output_path_is_one_line_and_no_file(tmp_path, gains, option, name, fragment):
    path = tmp_path / name
    result = _simulate(gains, *GOAL, option, str(path))
    _assert_one_line_error(result, fragment)
    assert not path.exists()
    assert [p.name for p in tmp_path.iterdir()] == ["gains.toml"]


def test_failed_simulate_keeps_existing_output_files(tmp_path, gains):
    out, plot = tmp_path / "t.csv", tmp_path / "t.png"
    out.write_text("old")
    plot.write_text("old")
    args = ("--goal", "0.30,0,0", "--out", str(out), "--plot", str(plot), "--force")
    result = _simulate(gains, *args)
    _assert_one_line_error(result, "behind the pushed face")
    assert out.read_text() == "old" and plot.read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["gains.toml", "t.csv", "t.png"]


# --- pushctl tune-pd ----------------------------------------------------------------------


def test_tune_pd_writes_gains_and_its_search_record(tmp_path):
    out = tmp_path / "g.toml"
    result = runner.invoke(app, ["tune-pd", *TUNE_BUDGET, "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert "PD gain search" in result.output
    text = out.read_text()
    assert text.splitlines()[0].startswith("# made by: pushctl tune-pd")
    chosen = load_gains(out)
    search = tomllib.loads(text)["search"]
    assert search["seed"] == 0 and search["per_case"] == 1
    assert search["objects"] == ["cube"] and search["profiles"] == ["chirp"]
    assert search["duration"] == 1.0 and search["stream"] == "tuning"
    rows = search["candidates_kp_kv_kx_objective"]
    assert search["candidates_evaluated"] == len(rows)
    assert len(rows) == len(list(itertools.product(*GRID.values())))  # grid only
    assert all(len(row) == 4 for row in rows)
    kp, kv, kx, objective = min(rows, key=lambda row: row[3])
    assert (chosen.kp, chosen.kv, chosen.kx_linear, chosen.kx_angular) == (kp, kv, kx, kx)
    assert search["best_objective"] == objective
    assert [p.name for p in tmp_path.iterdir()] == ["g.toml"]


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (["--objects", "sphere"], "cube, wedge"),
        (["--profiles", "zigzag"], "constant, trapezoid, chirp"),
        (["--per-case", "0"], "--per-case must be an integer >= 1"),
        (["--max-rounds", "-1"], "--max-rounds must be >= 0"),
    ],
)
def test_tune_pd_bad_input_is_one_line_and_no_file(tmp_path, args, fragment):
    out = tmp_path / "g.toml"
    # The tiny budget first, the bad option last (the last value of an option wins).
    result = runner.invoke(app, ["tune-pd", *TUNE_BUDGET, *args, "--out", str(out)])
    _assert_one_line_error(result, fragment)
    assert list(tmp_path.iterdir()) == []


def test_tune_pd_rejects_a_non_toml_output(tmp_path):
    out = tmp_path / "g.txt"
    result = runner.invoke(app, ["tune-pd", *TUNE_BUDGET, "--out", str(out)])
    _assert_one_line_error(result, "--out must end in .toml")
    assert list(tmp_path.iterdir()) == []


def test_the_feedback_controller_pushes_through_the_residual_path(tmp_path, gains):
    """--controller feedback: the same scenario as PD-only, pushed by PD + the PI law through
    the environment (on a plant without unknowns the law has little to correct: the push
    differs from PD-only's, but only a little)."""
    out_pd, out_fb = tmp_path / "pd.csv", tmp_path / "fb.csv"
    args = ("--scenario", "3", "--randomize")
    pd_run = _simulate(gains, *args, "--out", str(out_pd))
    fb_run = _simulate(gains, *args, "--controller", "feedback", "--out", str(out_fb))
    assert pd_run.exit_code == 0, pd_run.output
    assert fb_run.exit_code == 0, fb_run.output
    assert _plant(pd_run.output) == _plant(fb_run.output)
    import pandas as pd_

    a, b = (pd_.read_csv(p, comment="#") for p in (out_pd, out_fb))
    assert list(a.columns) == list(b.columns) and len(a) == len(b)
    assert (a["des_x"] == b["des_x"]).all()
    assert not a["obj_x"].equals(b["obj_x"])
    assert (a["obj_x"] - b["obj_x"]).abs().max() < 2e-3
