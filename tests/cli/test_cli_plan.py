"""``pushctl plan``: the CSV it writes, its provenance, and one-line errors with no file."""

import math

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from pushctl.cli import app

runner = CliRunner()

COLUMNS = (
    "t,x,y,theta,vx,vy,omega,ax,ay,alpha,icr_x,icr_y,force_n_des_1,force_t_des_1,"
    "force_n_des_2,force_t_des_2,tau_z_des_1,tau_z_des_2,tau_z_des,ne_residual"
).split(",")


def _plan(tmp_path, *args):
    out = tmp_path / "plan.csv"
    result = runner.invoke(app, ["plan", *args, "--out", str(out)])
    return result, out


def test_plan_writes_the_documented_csv(tmp_path):
    result, out = _plan(
        tmp_path, "--object", "wedge", "--profile", "chirp", "--goal", "0.62,0.03,30"
    )
    assert result.exit_code == 0, result.output
    assert "feasible" in result.output and "ICR" in result.output
    first_line = out.read_text().splitlines()[0]
    assert first_line.startswith("# made by: pushctl plan") and "commit" in first_line
    frame = pd.read_csv(out, comment="#")
    assert list(frame.columns) == COLUMNS
    assert len(frame) == 2001
    last = frame.iloc[-1]
    assert (last.x, last.y) == pytest.approx((0.62, 0.03), abs=1e-9)
    assert last.theta == pytest.approx(math.radians(30.0), abs=1e-9)
    assert frame.t.iloc[-1] == pytest.approx(20.0)
    assert (frame.force_n_des_1 > 0).all() and (frame.force_n_des_2 > 0).all()
    assert frame.ne_residual.max() < 1e-5
    torque = frame.tau_z_des_1 + frame.tau_z_des_2
    np.testing.assert_allclose(frame.tau_z_des, torque, atol=1e-8)


def test_same_arguments_give_identical_csv_rows(tmp_path):
    args = ("--profile", "trapezoid", "--goal", "0.6,0.02,20", "--duration", "10")
    first = _plan(tmp_path, *args)[1].read_text().splitlines()[1:]
    second = _plan(tmp_path, *args)[1].read_text().splitlines()[1:]
    assert first == second


def test_straight_push_has_no_icr(tmp_path):
    result, out = _plan(tmp_path, "--goal", "0.6,0,0")
    assert result.exit_code == 0, result.output
    assert "straight" in result.output
    frame = pd.read_csv(out, comment="#")
    assert frame.icr_x.isna().all()
    assert frame.drop(columns=["icr_x", "icr_y"]).notna().all().all()


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (["--goal", "abc"], "x,y,theta_deg"),
        (["--goal", "0.6,0.03"], "x,y,theta_deg"),
        (["--goal", "0.6,0.03,200"], "-180 to 180 deg"),
        (["--goal", "0.3,0,0"], "behind the pushed face"),
        (["--goal", "0.95,0.03,30"], "out of reach"),
        (["--goal", "0.62,-0.05,30"], "deg off the face normal"),
        (["--goal", "0.42,0,30"], "pure rotation"),
        (["--goal", "0.6,0,10", "--duration", "0"], "duration must be a positive"),
        (["--goal", "0.6,0,10", "--dt", "-0.01"], "dt must be a positive"),
        (["--goal", "0.6,0,10", "--dt", "0.03"], "whole number"),
        (["--goal", "0.6,0,10", "--profile", "sine"], "constant, trapezoid, chirp"),
        (["--goal", "0.6,0,10", "--object", "ball"], "cube, wedge"),
        (["--goal", "0.6,0,10", "--mu-contact", "-1"], "mu_contact"),
        (["--goal", "0.6,0,10", "--start", "0.42,0,nan"], "finite"),
        (["--goal", "0.6,0,10", "--plot", "p.jpg"], ".png"),
    ],
)
def test_bad_input_is_one_line_exit_2_and_no_file(tmp_path, args, fragment):
    result, out = _plan(tmp_path, *args)
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    error_lines = [line for line in result.output.splitlines() if line.startswith("error:")]
    assert len(error_lines) == 1 and fragment in error_lines[0], result.output
    assert not out.exists()
    assert list(tmp_path.iterdir()) == []


def test_missing_output_directory_is_reported_before_planning(tmp_path):
    result = runner.invoke(
        app, ["plan", "--goal", "0.6,0,10", "--out", str(tmp_path / "no" / "p.csv")]
    )
    assert result.exit_code == 2
    assert "does not exist" in result.output


def test_failed_plan_keeps_an_existing_output_file(tmp_path):
    out = tmp_path / "plan.csv"
    out.write_text("keep me\n")
    result = runner.invoke(app, ["plan", "--goal", "0.42,0,30", "--out", str(out)])
    assert result.exit_code == 2
    assert out.read_text() == "keep me\n"


def test_plot_and_csv_are_written_together(tmp_path):
    plot = tmp_path / "plan.png"
    result, out = _plan(tmp_path, "--goal", "0.6,0.02,15", "--plot", str(plot))
    assert result.exit_code == 0, result.output
    assert out.exists() and plot.read_bytes()[:4] == b"\x89PNG"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["plan.csv", "plan.png"]


def test_unwritable_output_is_one_line_exit_2(tmp_path, monkeypatch):
    import pushctl.files.provenance

    def refuse(path, write):
        raise PermissionError(13, "Permission denied", str(path))

    monkeypatch.setattr(pushctl.files.provenance, "write_atomic", refuse)
    result, out = _plan(tmp_path, "--goal", "0.6,0,10")
    assert result.exit_code == 2
    assert result.output.strip().splitlines()[-1].startswith("error: cannot write")
    assert "Permission denied" in result.output and "Traceback" not in result.output
    assert not out.exists()
