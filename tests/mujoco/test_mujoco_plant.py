"""The mujoco plant: evaluate, simulate and Push-v0 on MuJoCo with the same controllers."""

from __future__ import annotations

import pandas as pd
import pytest
from typer.testing import CliRunner

from pushctl.cli import app
from pushctl.control.pd import PDController
from pushctl.errors import ConfigError
from pushctl.evaluation.trials import TrialSpec
from pushctl.mujoco import MujocoWorld
from pushctl.task.env import PushEnv
from pushctl.task.env_config import EnvConfig

runner = CliRunner()


def test_evaluate_on_mujoco_writes_mujoco_rows(tmp_path):
    """The acceptance command: PD-only and RL-assisted (the shipped policy) on MuJoCo."""
    args = ["--plant", "mujoco", "--object", "cube", "--profile", "constant", "--trials", "2"]
    result = runner.invoke(app, ["evaluate", *args, "--out", str(tmp_path)])
    assert result.exit_code == 0, result.output
    trials = pd.read_csv(tmp_path / "trials.csv", comment="#")
    assert set(trials["plant"]) == {"mujoco"}
    assert sorted(trials["controller"]) == ["feedback", "feedback", "pd", "pd", "rl", "rl"]
    pd_rows = trials[trials["controller"] == "pd"]
    assert (pd_rows["translation_error_pct"] < 2.0).all()  # the PD tracks on MuJoCo too
    assert (trials["max_penetration"] < 1e-3).all()


def test_plant_choices_and_their_errors(tmp_path):
    from pushctl.cli.evaluate_steps import choose_plants

    assert choose_plants("both") == ("sim", "proxy")
    assert choose_plants("all") == ("sim", "proxy", "mujoco")
    assert choose_plants("mujoco") == ("mujoco",)
    assert TrialSpec().plants == ("sim", "proxy")  # the default evaluation is unchanged
    result = runner.invoke(app, ["evaluate", "--plant", "bullet", "--out", str(tmp_path)])
    assert result.exit_code != 0
    assert "accepted: sim, proxy, mujoco, both or all" in result.output
    assert "Traceback" not in result.output


def test_mujoco_plant_draws_the_sim_plants_scenario_and_runs_the_same_controller():
    """Paired with sim: the same seed gives the same goal and parameters; only the engine
    differs, and the controller is the same PD class acting on the arm's model."""
    options = {"object": "cube", "profile": "constant", "scenario_seed": 3}
    envs = {
        p: PushEnv(EnvConfig(plant=p, stream="evaluation", duration=1.0)) for p in ("sim", "mujoco")
    }
    for env in envs.values():
        env.reset(options=options)
    sim, mj = envs["sim"].episode, envs["mujoco"].episode
    assert sim is not None and mj is not None
    assert envs["sim"].scenario == envs["mujoco"].scenario
    assert isinstance(mj.world, MujocoWorld)
    assert type(mj.controller) is type(sim.controller) is PDController
    _, reward, _, _, info = envs["mujoco"].step(envs["mujoco"].action_space.sample() * 0)
    assert reward == reward  # finite, not NaN


def test_training_on_mujoco_is_refused():
    with pytest.raises(ConfigError, match="evaluation only"):
        EnvConfig(plant="mujoco")


def test_simulate_on_mujoco(tmp_path):
    out = tmp_path / "trace.csv"
    args = ["simulate", "--plant", "mujoco", "--goal", "0.55,0.02,15", "--duration", "10"]
    result = runner.invoke(app, [*args, "--out", str(out)])
    assert result.exit_code == 0, result.output
    trace = pd.read_csv(out, comment="#")
    pushing = trace["lambda_n_1"] + trace["lambda_n_2"]
    assert pushing.iloc[100:].mean() == pytest.approx(0.3 * 0.3 * 9.81, rel=0.1)
    assert (pushing.iloc[100:] > 1e-3).mean() > 0.95  # contact kept
    bad = runner.invoke(app, ["simulate", "--plant", "bullet", "--goal", "0.55,0.02,15"])
    assert bad.exit_code != 0 and "accepted: sim, proxy, mujoco" in bad.output


def test_proxy_effects_layer_on_mujoco():
    """Latency, joint friction, force noise and the camera act through the world's step, so
    they apply to either engine."""
    from pushctl.episode.metrics import compute_metrics
    from pushctl.episode.proxy import ProxyEffects
    from pushctl.episode.runner import Episode
    from pushctl.episode.scenario import Scenario
    from pushctl.types import PlanarPose

    goal = PlanarPose.from_degrees(0.55, 0.02, 15)
    scenario = Scenario(object="cube", profile="constant", goal=goal, seed=1, duration=6.0)
    episode = Episode(scenario, effects=ProxyEffects(), engine="mujoco")
    trace = episode.run()
    assert isinstance(episode.world, MujocoWorld)
    assert trace.measured_pose is not None  # the camera's poses
    assert compute_metrics(trace).translation_error_pct < 3.0


def test_the_forces_a_mujoco_plant_needs_leave_out_the_unknowns_it_does_not_carry():
    """MuJoCo's object rests on its own floor contact with one μ_g: no centre-of-pressure
    offset, no friction field (docs/mujoco.md). Its force reference (plant_forces, behind
    force_error and force_error_landed) must be the plant's needs without them, while our
    engine's keeps them; the recorded unknowns stay what was drawn."""
    from dataclasses import replace

    import numpy as np

    from pushctl.episode.draw import draw_planned_scenario
    from pushctl.episode.runner import Episode
    from pushctl.episode.unknowns import PlantUnknowns

    drawn, _, plan = draw_planned_scenario(4, "tuning", "cube", "constant", plant="sim")
    unknowns = PlantUnknowns(
        placement=(0.001, -0.001, 0.01),
        mount_yaw=0.01,
        prong_errors=((0.0005, 0.0005), (-0.0005, 0.0)),
        pressure_offset=(0.15, -0.1),
        ground_variation=0.15,
        ground_seed=7,
    )
    scenario = drawn.with_unknowns(unknowns)
    carried = drawn.with_unknowns(
        replace(unknowns, pressure_offset=(0.0, 0.0), ground_variation=0.0)
    )
    on_mujoco = Episode(scenario, plan=plan, engine="mujoco")
    assert on_mujoco.friction_field is None
    expected = Episode(carried, plan=plan).plant_forces.forces
    np.testing.assert_array_equal(on_mujoco.plant_forces.forces, expected)
    ours = Episode(scenario, plan=plan)
    assert ours.friction_field is not None
    assert np.abs(ours.plant_forces.forces - expected).max() > 1e-3  # [N]: they do act there
    assert on_mujoco.scenario.unknowns == unknowns
