"""Pusher files (``--pusher``, k = 1–4 prongs) and TOML objects on the command line: the
example files, one-line errors for bad ones, and the pushes they make.

The simulate runs are short (``--duration 2``) except the issue's acceptance command."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest
from typer.testing import CliRunner

from pushctl.arm.pusher_file import KEYS, load_pusher, pusher_to_toml, resolve_pusher
from pushctl.cli import app
from pushctl.config import PusherConfig
from pushctl.episode.scenario import PhysicalParameters, Scenario
from pushctl.errors import ConfigError
from pushctl.types import PlanarPose

ROOT = Path(__file__).resolve().parents[2]
PUSHERS = ROOT / "experiments" / "pushers"
HEXAGON = str(ROOT / "experiments" / "objects" / "hexagon.toml")
EXAMPLES = {"one.toml": 1, "two.toml": 2, "three.toml": 3, "four.toml": 4}

runner = CliRunner()


def _one_line_error(result, fragment: str) -> None:
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith("error:") and fragment in lines[0], result.stderr


@pytest.mark.parametrize(("name", "k"), EXAMPLES.items())
def test_example_pusher_files(name: str, k: int) -> None:
    pusher = load_pusher(PUSHERS / name)
    assert pusher.n_prongs == k
    assert pusher.prong_offsets().shape == (k,)
    assert load_pusher(PUSHERS / name) == pusher


def test_two_toml_is_the_papers_pusher() -> None:
    assert load_pusher(PUSHERS / "two.toml") == PusherConfig()


def test_pusher_round_trips_through_toml(tmp_path: Path) -> None:
    pusher = PusherConfig(n_prongs=3, prong_spacing=0.03, width=0.09, mass=0.05)
    path = tmp_path / "p.toml"
    path.write_text(pusher_to_toml(pusher))
    assert load_pusher(path) == pusher
    assert set(pusher_to_toml(pusher).split()[::3]) == set(KEYS)


@pytest.mark.parametrize(
    ("text", "fragment"),
    [
        ("n_prongs = 5\n", "n_prongs must be an integer in 1..4"),
        ("n_prongs = 2.0\n", "n_prongs must be an integer 1 … 4"),
        ("prongs = 2\n", "unknown key(s) prongs; accepted: n_prongs"),
        ("n_prongs = 4\nprong_spacing = 0.05\n", "wider than the 0.104 m plate"),
        ("mass = -1\n", "pusher mass must be a positive number"),
        ('width = "wide"\n', "width must be a number"),
        ("n_prongs = \n", "cannot read pusher file"),
    ],
)
def test_bad_pusher_files_fail_in_one_line(tmp_path: Path, text: str, fragment: str) -> None:
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(ConfigError) as caught:
        load_pusher(path)
    message = str(caught.value)
    assert fragment in message and "\n" not in message and "bad.toml" in message


def test_resolve_pusher() -> None:
    assert resolve_pusher(None) is None
    with pytest.raises(ConfigError, match="must be a .toml pusher file"):
        resolve_pusher("three")
    with pytest.raises(ConfigError, match="does not exist"):
        resolve_pusher("no/such/pusher.toml")


def test_the_pusher_files_mass_is_the_pusher_mass_unless_the_parameters_set_one() -> None:
    pusher = PusherConfig(n_prongs=3, prong_spacing=0.02, mass=0.05)
    goal = PlanarPose(0.62, 0.03, 0.3)
    scenario = Scenario(object="cube", profile="constant", goal=goal, pusher=pusher)
    assert scenario.pusher_mass(PhysicalParameters()) == 0.05
    assert scenario.pusher_mass(PhysicalParameters(pusher_mass=0.07)) == 0.07
    assert scenario.pusher_config(0.07) == PusherConfig(n_prongs=3, prong_spacing=0.02, mass=0.07)
    plain = Scenario(object="cube", profile="constant", goal=goal)
    assert plain.pusher_mass(PhysicalParameters()) is None  # the object's Table II value
    assert plain.pusher_config(0.04) == PusherConfig(mass=0.04)


def test_acceptance_simulate_three_prongs_on_the_hexagon(tmp_path: Path) -> None:
    """The issue's acceptance command, with the trace written: three prongs in contact."""
    out = tmp_path / "trace.csv"
    result = runner.invoke(
        app,
        ["simulate", "--pusher", str(PUSHERS / "three.toml"), "--object", HEXAGON,
         "--goal", "0.62,0.03,20", "--out", str(out)],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    trace = pd.read_csv(out, comment="#")
    assert {"lambda_n_3", "force_n_des_3"} <= set(trace.columns)
    assert "lambda_n_4" not in trace.columns
    pushing = trace[[f"lambda_n_{i}" for i in (1, 2, 3)]].iloc[len(trace) // 2]
    assert (pushing > 0.0).all(), pushing  # every prong pushes mid-way
    assert "--pusher" in out.read_text().splitlines()[0]  # the provenance line names it


@pytest.mark.parametrize(("name", "k"), [("one.toml", 1), ("four.toml", 4)])
def test_plan_with_k_prongs(tmp_path: Path, name: str, k: int) -> None:
    out = tmp_path / "plan.csv"
    result = runner.invoke(
        app,
        ["plan", "--pusher", str(PUSHERS / name), "--goal", "0.62,0.03,20", "--out", str(out)],
    )
    assert result.exit_code == 0, result.output
    columns = pd.read_csv(out, comment="#").columns
    prongs = {c.rsplit("_", 1)[1] for c in columns if c.startswith("force_n")}
    assert prongs == {str(i) for i in range(1, k + 1)}, list(columns)


def test_plan_reports_prongs_too_wide_for_the_face() -> None:
    result = runner.invoke(
        app, ["plan", "--pusher", str(PUSHERS / "four.toml"), "--object", HEXAGON,
              "--goal", "0.62,0.03,20"],
    )  # fmt: skip
    assert result.exit_code == 2, result.output
    assert "prongs span 75.0 mm" in result.stderr


def test_simulate_feedback_with_one_prong() -> None:
    result = runner.invoke(
        app, ["simulate", "--pusher", str(PUSHERS / "one.toml"), "--controller", "feedback",
              "--goal", "0.6,0.0,10", "--duration", "2"],
    )  # fmt: skip
    assert result.exit_code == 0, result.output


@pytest.mark.parametrize("command", ["plan", "simulate", "evaluate"])
def test_bad_pusher_file_on_the_command_line(tmp_path: Path, command: str) -> None:
    bad = tmp_path / "bad.toml"
    bad.write_text("n_prongs = 7\n")
    args = [command, "--pusher", str(bad)]
    args += ["--goal", "0.62,0.03,20"] if command != "evaluate" else ["--controller", "pd"]
    if command == "evaluate":
        args += ["--out", str(tmp_path / "ev")]
    _one_line_error(runner.invoke(app, args), "n_prongs must be an integer in 1..4")


def test_rl_refuses_another_pusher(tmp_path: Path) -> None:
    three = str(PUSHERS / "three.toml")
    _one_line_error(
        runner.invoke(
            app, ["simulate", "--pusher", three, "--controller", "rl", "--goal", "0.62,0.03,20"]
        ),  # fmt: skip
        "--pusher runs with --controller pd or feedback",
    )
    _one_line_error(
        runner.invoke(app, ["evaluate", "--pusher", three, "--out", str(tmp_path / "ev")]),
        "--pusher runs with --controller pd or feedback",
    )


def test_evaluate_a_toml_object_with_three_prongs(tmp_path: Path) -> None:
    out = tmp_path / "ev"
    result = runner.invoke(
        app,
        ["evaluate", "--object", HEXAGON, "--pusher", str(PUSHERS / "three.toml"),
         "--profile", "constant", "--controller", "feedback", "--plant", "sim",
         "--trials", "1", "--out", str(out)],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    trials = pd.read_csv(out / "trials.csv", comment="#")
    assert list(trials["controller"]) == ["feedback"]
    assert list(trials["object"]) == [HEXAGON]
    assert trials["translation_error_pct"].notna().all()


def test_evaluate_refuses_a_bad_object_file(tmp_path: Path) -> None:
    bad = tmp_path / "blob.toml"
    bad.write_text("mass = 1\n")
    result = runner.invoke(app, ["evaluate", "--object", str(bad), "--out", str(tmp_path / "e")])
    _one_line_error(result, "blob.toml")


def test_evaluate_on_the_tuning_stream(tmp_path: Path) -> None:
    """--stream tuning draws other targets than the evaluation's, and says so."""
    goals = {}
    for stream in ("tuning", "evaluation"):
        out = tmp_path / stream
        result = runner.invoke(
            app,
            ["evaluate", "--object", "cube", "--profile", "constant", "--controller", "pd",
             "--plant", "sim", "--trials", "1", "--stream", stream, "--out", str(out)],
        )  # fmt: skip
        assert result.exit_code == 0, result.output
        text = (out / "trials.csv").read_text()
        assert f"({stream} stream)" in text.splitlines()[0]
        goals[stream] = pd.read_csv(out / "trials.csv", comment="#")["goal_dx"].iloc[0]
    assert goals["tuning"] != goals["evaluation"]
    _one_line_error(
        runner.invoke(app, ["evaluate", "--stream", "training", "--out", str(tmp_path / "t")]),
        "unknown --stream 'training'; accepted: evaluation, tuning",
    )


@pytest.mark.parametrize("command", ["info", "plan"])
def test_the_hexagon_on_info_and_plan(command: str) -> None:
    args = [command, "--object", HEXAGON]
    if command == "plan":
        args += ["--pusher", str(PUSHERS / "three.toml"), "--goal", "0.62,0.03,20"]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    assert "hexagon" in result.output
