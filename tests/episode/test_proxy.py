"""The reality proxy (docs/design.md §7, §9): each effect against what it must agree with.

Latency against the undelayed world shifted by one step; joint friction against the
analytic deceleration of a coasting joint; the camera's hold, noise statistics and
noiseless metrics; the force estimate's noise statistics; reproducibility and pairing from
the scenario's seed; the environment's proxy observation; full pushes that stay stable.
"""

from __future__ import annotations

import copy
import math
from dataclasses import fields, replace

import numpy as np
import pytest

from pushctl.control import PDGains
from pushctl.engines import make_world
from pushctl.episode import Episode, Scenario
from pushctl.episode.draw import draw_planned_scenario
from pushctl.episode.metrics import compute_metrics
from pushctl.episode.proxy import (
    PROXY_STREAM,
    ProxyActuators,
    ProxyEffects,
    camera_frames,
    camera_poses,
    draw_camera_noise,
    effects_for,
)
from pushctl.episode.scenario import STREAMS
from pushctl.episode.unknowns import NO_UNKNOWNS
from pushctl.errors import ConfigError
from pushctl.task.env import PushEnv
from pushctl.task.env_config import EnvConfig
from pushctl.task.spaces import index
from pushctl.types import PlanarPose

GAINS = PDGains(kp=0, kv=100, kx_linear=50, kx_angular=50)
TURNING_GOAL = PlanarPose(0.50, 0.01, math.radians(15.0))
QUIET = dict(camera_sigma_position=0.0, camera_sigma_angle=0.0)
NO_FRICTION = dict(coulomb_friction=(0.0,), viscous_friction=(0.0,))


def short_scenario(seed: int = 11, object_name: str = "cube") -> Scenario:
    """A 2 s turning push: 200 steps, enough for every effect to show."""
    return Scenario(
        object=object_name, profile="trapezoid", goal=TURNING_GOAL, duration=2.0, seed=seed
    )


# ------------------------------------------------------------------ settings


def test_effects_for_names_the_proxy_only() -> None:
    assert effects_for("proxy") == ProxyEffects()
    for plant in (None, "sim", "nominal"):
        assert effects_for(plant) is None
    with pytest.raises(ConfigError, match="unknown plant 'real'"):
        effects_for("real")


def test_the_defaults_are_design_section_9s() -> None:
    effects = ProxyEffects()
    assert effects.latency_steps == 1
    assert (effects.force_noise_relative, effects.force_noise_floor) == (0.05, 0.02)
    assert effects.camera_rate == 30.0
    assert effects.camera_sigma_position == 1e-3
    assert math.degrees(effects.camera_sigma_angle) == pytest.approx(0.5)
    assert len(effects.coulomb_friction) == len(effects.viscous_friction) == 7


@pytest.mark.parametrize(
    "change",
    [
        {"latency_steps": -1},
        {"latency_steps": 1.0},
        {"latency_steps": True},
        {"coulomb_friction": ()},
        {"coulomb_friction": (1.0, -0.1)},
        {"viscous_friction": (math.nan,)},
        {"friction_velocity": 0.0},
        {"force_noise_relative": -0.05},
        {"force_noise_floor": math.inf},
        {"camera_rate": 0.0},
        {"camera_sigma_position": -1e-3},
        {"camera_sigma_angle": "0.5"},
    ],
)
def test_bad_settings_raise_one_line_config_errors(change) -> None:
    with pytest.raises(ConfigError) as raised:
        ProxyEffects(**change)
    message = str(raised.value)
    assert "\n" not in message and next(iter(change)) in message


def test_friction_per_joint_must_fit_the_arm() -> None:
    with pytest.raises(ConfigError, match="3 values for an arm of 7 joints"):
        Episode(short_scenario(), GAINS, effects=ProxyEffects(coulomb_friction=(1.0,) * 3))


def test_the_proxy_stream_is_not_a_scenario_stream() -> None:
    assert PROXY_STREAM not in STREAMS.values()


# ------------------------------------------------------------------ latency


def test_a_torque_step_reaches_the_joints_one_step_later() -> None:
    """Open-loop commands, an arm at rest holding its weight, a 0.5 N·m step on the wrist at
    step 5: the delayed world is the undelayed one shifted by exactly one step."""
    worlds = [make_world("cube"), make_world("cube")]
    hold = worlds[0].gravity_torque()
    step = np.zeros(7)
    step[6] = 0.5
    commands = [hold if n < 5 else hold + step for n in range(15)]
    delayed = ProxyActuators(ProxyEffects(latency_steps=1, **NO_FRICTION), 7, hold)
    direct = [worlds[0].step(tau, implicit_kv=5.0).arm_v for tau in commands]
    late = [delayed.step(worlds[1], tau, 5.0)[0].arm_v for tau in commands]
    assert abs(direct[5][6]) > 0.02  # the step moves the wrist at once without latency
    np.testing.assert_allclose(late[5], 0.0, atol=1e-12)  # …and one step later with it
    np.testing.assert_allclose(np.array(late[1:]), np.array(direct[:-1]), rtol=0, atol=1e-12)


def test_the_episode_applies_each_command_one_step_late(monkeypatch) -> None:
    """The first push step applies the approach's last command; the trace records the
    applied torque minus the implicit K_v q̇."""
    episode = Episode(short_scenario(), GAINS, effects=ProxyEffects(**NO_FRICTION))
    commanded, applied = [], []
    command, world_step = episode.controller.command, episode.world.step

    def spy_command(*args, **kwargs):
        result = command(*args, **kwargs)
        commanded.append(result.tau.copy())
        return result

    def spy_step(tau, implicit_kv=None):
        applied.append(np.array(tau, copy=True))
        return world_step(tau, implicit_kv=implicit_kv)

    monkeypatch.setattr(episode.controller, "command", spy_command)
    monkeypatch.setattr(episode.world, "step", spy_step)
    hold = episode.world.gravity_torque()  # before reset: the ready pose, where reset starts
    episode.reset()
    approach = len(commanded)
    for _ in range(3):
        episode.step()
    np.testing.assert_array_equal(applied[0], hold)
    for n in range(1, len(applied)):
        np.testing.assert_array_equal(applied[n], commanded[n - 1])
    trace = episode.trace()
    expected = commanded[approach - 1] - GAINS.kv * trace.arm_v[1]
    np.testing.assert_allclose(trace.arm_tau[1], expected, rtol=0, atol=1e-12)


# ------------------------------------------------------------------ joint friction


def test_a_coasting_joint_decelerates_at_the_coulomb_plus_viscous_rate() -> None:
    """Joint 1 (vertical axis: no gravity torque, M_11 constant in q_1) coasts from 0.4 rad/s
    with the others held by a stiff damping: M_11 v̇ = −F_c − b v until it stops, so
    v(t) = (v0 + F_c/b) e^{−b t / M_11} − F_c/b; then it stays stopped, never reversing."""
    coulomb, viscous, v0 = 0.5, 0.5, 0.4
    effects = ProxyEffects(
        latency_steps=0, coulomb_friction=(coulomb,), viscous_friction=(viscous,)
    )
    world = make_world("cube")
    world.reset(arm_v=[v0, 0, 0, 0, 0, 0, 0])
    m11 = world.arm_terms.M[0, 0]
    actuators = ProxyActuators(effects, 7, world.gravity_torque())
    lock = np.array([0.0] + [1e4] * 6)  # the other joints held still
    speeds = [v0]
    for _ in range(40):
        speeds.append(actuators.step(world, world.gravity_torque(), lock)[0].arm_v[0])
    speeds = np.array(speeds)
    t = np.arange(len(speeds)) * world.config.dt
    analytic = (v0 + coulomb / viscous) * np.exp(-viscous * t / m11) - coulomb / viscous
    sliding = analytic > 0.1
    assert sliding.sum() >= 8
    np.testing.assert_allclose(speeds[sliding], analytic[sliding], rtol=0, atol=4e-3)
    stop = t[np.argmax(analytic < 0.0)]  # the analytic stopping time
    assert np.all(np.abs(speeds[t > stop + 0.03]) < 2e-3)
    assert speeds.min() > -1e-6


def test_the_friction_law_opposes_the_velocity() -> None:
    actuators = ProxyActuators(ProxyEffects(), 7, np.zeros(7))
    v = np.array([0.2, -0.2, 5e-4, -5e-4, 0.0, 0.05, -1.0])
    torque = actuators.friction_torque(v)
    assert np.all((torque * v)[v != 0.0] < 0.0)
    assert torque[4] == 0.0
    assert torque[0] == pytest.approx(-(1.0 + 0.5 * 0.2))  # a large joint sliding
    assert torque[6] == pytest.approx(0.5 + 0.2)  # a small joint sliding backwards
    assert torque[2] == pytest.approx(-1.0 * 0.5 - 0.5 * 5e-4)  # below v_s = 1 mrad/s: linear
    # In steady sliding the secant damping gives the law's torque exactly.
    np.testing.assert_allclose(-actuators.friction_damping(v) * v, torque, rtol=1e-12)


def test_zero_latency_and_friction_reproduce_the_sim_world_bit_for_bit() -> None:
    scenario = short_scenario()
    sim = Episode(scenario, GAINS).run()
    effects = ProxyEffects(latency_steps=0, **NO_FRICTION)
    proxy = Episode(scenario, GAINS, effects=effects).run()
    assert sim.measured_pose is None and proxy.measured_pose is not None
    for item in fields(sim):
        if item.name != "measured_pose":
            value = getattr(sim, item.name)
            assert np.array_equal(value, getattr(proxy, item.name)), item.name


# ------------------------------------------------------------------ camera

DT = 0.01


def test_the_camera_holds_each_frame_until_the_next_tick() -> None:
    t = np.arange(301) * DT  # 3 s
    pose = np.column_stack([0.4 + 0.01 * t, -0.02 * t, 0.1 * t])  # a steady motion
    seen = camera_poses(t, pose, 30.0, np.zeros((camera_frames(3.0, 30.0), 3)))
    frame = np.floor(t * 30.0 + 1e-9).astype(int)
    changes = np.flatnonzero(np.any(np.diff(seen, axis=0) != 0.0, axis=1)) + 1
    np.testing.assert_array_equal(changes, np.flatnonzero(np.diff(frame)) + 1)
    assert len(changes) == 90  # 30 Hz for 3 s
    # Each frame is the true pose at its own instant k / 30 s (never a later one).
    taken = frame / 30.0
    expected = np.column_stack([0.4 + 0.01 * taken, -0.02 * taken, 0.1 * taken])
    np.testing.assert_allclose(seen, expected, rtol=0, atol=1e-15)
    assert np.all(taken <= t + 1e-12)


def test_the_camera_noise_has_the_set_standard_deviations() -> None:
    effects = ProxyEffects()
    frames = camera_frames(300.0, effects.camera_rate)  # 9001 frames
    noise = draw_camera_noise(effects, frames, np.random.default_rng(3))
    t = np.arange(30001) * DT
    pose = np.tile([0.5, 0.02, 0.3], (len(t), 1))
    seen = camera_poses(t, pose, effects.camera_rate, noise)
    per_frame = seen[np.flatnonzero(np.diff(np.floor(t * 30.0 + 1e-9), prepend=-1))] - pose[0]
    assert len(per_frame) == frames
    sigma = [effects.camera_sigma_position] * 2 + [effects.camera_sigma_angle]
    np.testing.assert_allclose(per_frame.std(axis=0), sigma, rtol=0.04)  # ≈ 5 standard errors
    assert np.all(np.abs(per_frame.mean(axis=0)) < 4 * np.array(sigma) / math.sqrt(frames))


def test_a_noiseless_camera_changes_the_metrics_by_at_most_its_hold_error() -> None:
    trace = Episode(short_scenario(), GAINS, effects=ProxyEffects(**QUIET)).run()
    exact = compute_metrics(replace(trace, measured_pose=None))
    seen = compute_metrics(trace)
    hold = np.linalg.norm(trace.measured_pose[1:, :2] - trace.object_pose[1:, :2], axis=1).max()
    hold_angle = np.abs(trace.measured_pose[1:, 2] - trace.object_pose[1:, 2]).max()
    speed = np.linalg.norm(np.diff(trace.object_pose[:, :2], axis=0), axis=1).max() / DT
    assert 0.0 < hold <= speed * (1 / 30 + DT)  # at most one frame period (and a step) old
    bound = 100.0 * hold / trace.arc_length
    assert seen.translation_error_pct != exact.translation_error_pct
    assert abs(seen.translation_error_pct - exact.translation_error_pct) <= bound
    angle_bound = 100.0 * hold_angle / abs(trace.delta_theta)
    assert abs(seen.angle_error_pct - exact.angle_error_pct) <= angle_bound
    assert seen.force_error == exact.force_error  # forces are never the camera's


# ------------------------------------------------------------------ force estimate


def test_the_force_noise_is_five_percent_of_the_reading_plus_twenty_millinewtons() -> None:
    effects = ProxyEffects()
    forces = np.tile([0.0, 2.0, -0.5], (20000, 1))
    noisy = effects.noisy_forces(forces, np.random.default_rng(5))
    sigma = np.array([0.02, 0.05 * 2.0 + 0.02, 0.05 * 0.5 + 0.02])
    np.testing.assert_allclose(noisy.std(axis=0), sigma, rtol=0.03)
    assert np.all(np.abs(noisy.mean(axis=0) - forces[0]) < 4 * sigma / math.sqrt(20000))
    assert np.all(forces[:, 1] == 2.0)  # the reading itself is left alone


# ------------------------------------------------------------------ seeds and pairing


def _camera_noise(trace) -> np.ndarray:
    """What the camera added to the (held) true pose, (N+1, 3)."""
    frames = camera_frames(float(trace.t[-1]), 30.0)
    return trace.measured_pose - camera_poses(
        trace.t, trace.object_pose, 30.0, np.zeros((frames, 3))
    )


def test_one_seed_gives_identical_traces() -> None:
    effects = ProxyEffects()
    first = Episode(short_scenario(), GAINS, effects=effects)
    a = first.run()
    b = Episode(short_scenario(), GAINS, effects=effects).run()
    c = first.run()  # reset re-creates the generators
    for other in (b, c):
        assert a.to_frame().to_numpy().tobytes() == other.to_frame().to_numpy().tobytes()
    d = Episode(short_scenario(seed=12), GAINS, effects=effects).run()
    assert not np.array_equal(_camera_noise(a), _camera_noise(d))
    wedge = Episode(short_scenario(object_name="wedge"), GAINS, effects=effects).run()
    assert not np.allclose(_camera_noise(a), _camera_noise(wedge), atol=1e-6)


def test_a_copy_of_a_reset_proxy_episode_finishes_the_same_push() -> None:
    # The latency buffer, friction state and noise generators travel with a deepcopy.
    effects = ProxyEffects()
    fresh = Episode(short_scenario(), GAINS, effects=effects).run()
    episode = Episode(short_scenario(), GAINS, effects=effects)
    episode.reset()
    copied = copy.deepcopy(episode)
    for _ in range(20):
        episode.step(np.array([0.0, 0.01, 0.0]))
    assert copied.finish().to_frame().to_numpy().tobytes() == fresh.to_frame().to_numpy().tobytes()


def test_pd_only_and_rl_assisted_runs_see_the_same_camera_noise() -> None:
    effects = ProxyEffects()
    pd_only = Episode(short_scenario(), GAINS, effects=effects).run()
    assisted = Episode(short_scenario(), GAINS, effects=effects)
    assisted.reset()
    rng = np.random.default_rng(0)
    while not assisted.done:
        assisted.measured_forces(np.ones((2, 2)))  # a policy reading forces draws from its own
        assisted.step(rng.uniform(-0.01, 0.01, size=3))
    rl = assisted.trace()
    assert np.abs(rl.object_pose - pd_only.object_pose).max() > 1e-5  # the residual acted
    np.testing.assert_allclose(_camera_noise(rl), _camera_noise(pd_only), rtol=0, atol=1e-12)
    assert np.abs(_camera_noise(rl)[:, :2]).max() > 1e-4  # and there is noise to share


# ------------------------------------------------------------------ environment

OPTIONS = {"object": "cube", "profile": "trapezoid", "scenario_seed": 3}


@pytest.mark.parametrize("camera", [True, False])
def test_the_proxy_environment_observes_noisy_forces_and_the_cameras_pose_errors(
    camera: bool,
) -> None:
    """The observation's pose error reads the camera (docs/design.md §7), or with
    ``observe_camera = false`` (policies trained before) the exact pose."""
    env = PushEnv(EnvConfig(plant="proxy", duration=2.0, observe_camera=camera))
    assert env.effects == ProxyEffects()
    obs, _ = env.reset(options=OPTIONS)
    where = index(env.observation_entries)
    for _ in range(20):
        obs, *_ = env.step(np.zeros(3, dtype=np.float32))
    episode = env.episode
    assert episode is not None and episode.effects == env.effects
    trace = episode.trace()
    n = episode.step_index
    true = trace.contact_forces[n]
    seen = np.array([[obs[where[f"force_{c}_{i + 1}"]] for c in "nt"] for i in range(2)])
    sigma = 0.05 * np.abs(true) + 0.02
    assert np.all(seen != true.astype(np.float32))
    assert np.all(np.abs(seen - true) < 6 * sigma)
    seen_pose = trace.measured_pose if camera else trace.object_pose
    error = trace.desired_pose[n] - seen_pose[n]
    assert obs[where["error_theta"]] == pytest.approx(error[2], rel=1e-5, abs=1e-12)
    other = trace.object_pose if camera else trace.measured_pose
    assert abs((trace.desired_pose[n] - other[n])[2] - error[2]) > 1e-5  # they differ
    # The paired PD-only run of the evaluation sees the same camera noise.
    for _ in range(n, episode.n_steps):
        env.step(np.zeros(3, dtype=np.float32))
    pd_only = Episode(env.scenario, env.gains, plan=env.plan, effects=env.effects).run()
    np.testing.assert_allclose(
        _camera_noise(pd_only), _camera_noise(episode.trace()), rtol=0, atol=1e-12
    )


def test_the_sim_environment_has_no_proxy() -> None:
    env = PushEnv(EnvConfig(plant="sim", duration=2.0))
    assert env.effects is None
    obs, _ = env.reset(options=OPTIONS)
    episode = env.episode
    assert episode is not None and episode.effects is None
    where = index(env.observation_entries)
    assert obs[where["force_n_1"]] == np.float32(episode.trace().contact_forces[0, 0, 0])


# ------------------------------------------------------------------ full pushes


@pytest.mark.parametrize("object_name", ["cube", "wedge"])
def test_a_full_proxy_push_stays_stable(object_name) -> None:
    """20 s, trapezoid, the shipped gains, every proxy effect: finite, tracking, no blow-up.
    Without the plant unknowns (they leave open-loop PD-only offset, and can lose the wedge
    off a prong: tests/episode/test_plant_unknowns.py), so the bounds are the actuators' and
    sensors'."""
    scenario, _, plan = draw_planned_scenario(
        0, "evaluation", object_name, "trapezoid", plant="proxy"
    )
    scenario = scenario.with_unknowns(NO_UNKNOWNS)
    trace = Episode(scenario, plan=plan, effects=effects_for("proxy")).run()
    for item in ("object_pose", "measured_pose", "contact_forces", "arm_v", "arm_tau"):
        assert np.all(np.isfinite(getattr(trace, item))), item
    metrics = compute_metrics(trace)
    assert metrics.max_penetration < 1e-3
    assert metrics.translation_error_pct < 3.0
    assert metrics.final_position_error < 5e-3
    assert np.abs(trace.arm_v).max() < 0.63  # the joints' velocity limit
