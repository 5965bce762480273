"""The push environment: gymnasium's checker, the observation and action tables against the
code, the reward against the trace, the gate, seeding and bad input."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import pushctl.task
from pushctl.episode.metrics import compute_metrics
from pushctl.episode.runner import Episode
from pushctl.episode.trace import prong_torques
from pushctl.episode.unknowns import NO_UNKNOWNS
from pushctl.errors import ConfigError, StateError
from pushctl.rl.policy import finish_with_policy
from pushctl.task.env import PushEnv
from pushctl.task.env_config import EnvConfig
from pushctl.task.spaces import ACTION_ENTRIES, index, markdown_table, observation_entries

LEARNING_PAGE = Path(__file__).resolve().parents[2] / "docs" / "learning.md"
SHORT = EnvConfig(
    duration=2.0, landing="believed"
)  # 200 push steps (shorter chirps can need a pull)
# (the prongs where the approach landed them, as PD-only's: tests/rl/test_landing.py re-lands)
OPTIONS = {"object": "wedge", "profile": "trapezoid", "scenario_seed": 3}
ERROR_NAMES = ("error_x", "error_y", "error_theta")


@pytest.fixture(scope="module")
def env() -> PushEnv:
    return PushEnv(SHORT)


def _rotate_to(yaw: float, x: float, y: float) -> tuple[float, float]:
    c, s = math.cos(yaw), math.sin(yaw)
    return c * x + s * y, -s * x + c * y


@pytest.mark.filterwarnings("ignore:.*Box observation space m")  # unbounded on purpose
def test_gymnasium_env_checker_passes(env: PushEnv) -> None:
    check_env(env, skip_render_check=True)


def test_the_registered_id_makes_the_environment() -> None:
    made = gymnasium.make(pushctl.task.ENV_ID, config=SHORT)
    assert isinstance(made.unwrapped, PushEnv)
    obs, _ = made.reset(seed=1)
    assert made.observation_space.contains(obs)


def test_observation_entries_match_the_state_they_name(env: PushEnv) -> None:
    env.reset(options=OPTIONS)
    for _ in range(7):
        obs, *_ = env.step(np.array([0.3, -0.2, 0.5], dtype=np.float32))
    episode = env.episode
    assert episode is not None
    where = index(env.observation_entries)
    n = episode.step_index
    trace = episode.trace()
    yaw = env.plan.trajectory.pose[n, 2]
    for i in range(2):
        planned = env.plan.forces.forces[n + 1, i]
        assert obs[where[f"force_n_des_{i + 1}"]] == pytest.approx(planned[0], rel=1e-6)
        assert obs[where[f"force_t_des_{i + 1}"]] == pytest.approx(planned[1], rel=1e-6)
        measured = trace.contact_forces[n, i]
        assert obs[where[f"force_n_{i + 1}"]] == pytest.approx(measured[0], rel=1e-6, abs=1e-9)
        assert obs[where[f"force_t_{i + 1}"]] == pytest.approx(measured[1], rel=1e-6, abs=1e-9)
    error = trace.desired_pose[n] - trace.object_pose[n]
    along, across = _rotate_to(yaw, error[0], error[1])
    assert obs[where["error_x"]] == pytest.approx(along, rel=1e-5, abs=1e-12)
    assert obs[where["error_y"]] == pytest.approx(across, rel=1e-5, abs=1e-12)
    assert obs[where["error_theta"]] == pytest.approx(error[2], rel=1e-5, abs=1e-12)
    # The pusher's velocity from finite differences of its traced position.
    velocity = (trace.pusher_position[n] - trace.pusher_position[n - 1]) / SHORT.dt
    vx, vy = _rotate_to(yaw, velocity[0], velocity[1])
    assert obs[where["pusher_vx"]] == pytest.approx(vx, abs=2e-4)
    assert obs[where["pusher_vy"]] == pytest.approx(vy, abs=2e-4)
    assert obs[where["phase"]] == pytest.approx(n / episode.n_steps)


def test_the_observation_is_its_parts_as_float32_bit_for_bit() -> None:
    """observation() builds the array from Python floats; it must hold the float32s of its
    parts concatenated as float64 arrays, the offset's rows included."""
    env = PushEnv(replace(SHORT, gate_threshold=0.0, observe_offset=True))
    env.reset(options=OPTIONS)
    rng = np.random.default_rng(5)
    for _ in range(40):
        obs, *_ = env.step(rng.uniform(-1, 1, 3).astype(np.float32))
        episode = env.episode
        assert episode is not None and episode.world.arm_terms is not None
        n = episode.step_index
        yaw = env.plan.trajectory.pose[n, 2]
        c, s = math.cos(yaw), math.sin(yaw)
        twist = episode.world.arm_terms.pusher_jacobian @ episode.world.v
        planned = env.plan.forces.forces[n + 1]
        measured, offset = env.measured_forces, episode.reference_offset
        parts = [
            planned[:, 0], planned[:, 1], measured[:, 0], measured[:, 1],
            [c * twist[0] + s * twist[1], -s * twist[0] + c * twist[1], twist[5]],
            env.pose_error,
            [c * offset[0] + s * offset[1], -s * offset[0] + c * offset[1], offset[2]],
            [n / episode.n_steps],
        ]  # fmt: skip
        assert obs.tobytes() == np.concatenate(parts, dtype=np.float32).tobytes()


def test_an_action_steps_alike_as_float32_float64_or_a_list() -> None:
    """step()'s fast path for float arrays and its general path for anything else take the
    same floats: three environments, one action in three forms, identical steps."""
    envs = [PushEnv(replace(SHORT, gate_threshold=0.0, residual_scale=0.7)) for _ in range(3)]
    for env in envs:
        env.reset(options=OPTIONS)
    rng = np.random.default_rng(6)
    for _ in range(30):
        action = rng.uniform(-1.5, 1.5, 3).astype(np.float32)  # some beyond the clip
        forms = (action, action.astype(np.float64), action.tolist())
        steps = [env.step(form) for env, form in zip(envs, forms, strict=True)]
        first = steps[0]
        for other in steps[1:]:
            assert other[0].tobytes() == first[0].tobytes()
            assert other[1] == first[1]
            assert other[4]["residual"].tobytes() == first[4]["residual"].tobytes()


def test_the_action_is_a_plan_frame_twist_scaled_and_rotated_to_the_world() -> None:
    env = PushEnv(replace(SHORT, gate_threshold=0.0))
    env.reset(options=OPTIONS)
    yaw = env.plan.trajectory.pose[0, 2]
    _, _, _, _, info = env.step(np.array([1.0, 0.5, -1.0]))
    assert info["residual_active"]
    expected = [
        SHORT.action_scale_linear * (math.cos(yaw) - 0.5 * math.sin(yaw)),
        SHORT.action_scale_linear * (math.sin(yaw) + 0.5 * math.cos(yaw)),
        -SHORT.action_scale_angular,
    ]
    np.testing.assert_allclose(info["residual"], expected, rtol=1e-12)
    assert [entry.name for entry in ACTION_ENTRIES] == ["residual_x", "residual_y", "residual_wz"]


def test_the_reward_terms_are_eq_17_against_the_plant_force_plan(env: PushEnv) -> None:
    env.reset(options=OPTIONS)
    rewards, terms = [], np.zeros(3)
    for _ in range(30):
        _, reward, _, _, info = env.step(env.action_space.sample())
        parts = [info["reward_normal"], info["reward_tangential"], info["reward_torque"]]
        assert info["reward_pose"] == 0.0
        assert all(part <= 0.0 for part in parts)
        assert reward == pytest.approx(sum(parts))
        rewards.append(reward)
        terms += parts
    episode = env.episode
    assert episode is not None
    trace = episode.trace()
    plant = episode.plant_forces
    rows = slice(1, 31)
    force_error = np.abs(plant.forces[rows] - trace.contact_forces[rows])
    torques = prong_torques(
        trace.object_pose[rows], episode._rows.prongs[rows], trace.contact_forces[rows]
    )
    assert terms[0] == pytest.approx(-SHORT.w_normal * force_error[:, :, 0].sum(), rel=1e-9)
    assert terms[1] == pytest.approx(-SHORT.w_tangential * force_error[:, :, 1].sum(), rel=1e-9)
    expected_torque = -SHORT.w_torque * np.abs(plant.torques[rows] - torques).sum()
    assert terms[2] == pytest.approx(expected_torque, rel=1e-9)
    # The nominal plan differs: the reward really uses the plant's parameters.
    nominal = np.abs(env.plan.forces.forces[rows] - trace.contact_forces[rows])[:, :, 0].sum()
    assert abs(nominal - force_error[:, :, 0].sum()) > 1e-3


def test_a_pose_weight_adds_the_gate_deviation_as_a_penalty() -> None:
    env = PushEnv(replace(SHORT, w_pose=20.0))
    env.reset(options=OPTIONS)
    _, reward, _, _, info = env.step(np.zeros(3))
    assert info["reward_pose"] < 0.0
    parts = ("reward_normal", "reward_tangential", "reward_torque", "reward_pose")
    assert reward == pytest.approx(sum(info[name] for name in parts))


@pytest.mark.parametrize("plant", ["sim", "proxy"])
def test_the_metrics_term_sums_to_the_tables_two_errors(plant: str) -> None:
    """With ``w_metrics`` = 1 and a decision every step, minus the mean of a push's
    ``reward_metrics`` is its translation_error_pct + angle_error_pct of the true pose (on
    the proxy the tables read the camera's); the other terms are eq. 17's as without it."""
    config = replace(SHORT, plant=plant, w_metrics=1.0, action_repeat=1)
    env, plain = PushEnv(config), PushEnv(replace(config, w_metrics=0.0))
    env.reset(options=OPTIONS)
    plain.reset(options=OPTIONS)
    terms, done = [], False
    while not done:
        _, reward, done, _, info = env.step(np.zeros(3))
        _, plain_reward, _, _, plain_info = plain.step(np.zeros(3))
        assert plain_info["reward_metrics"] == 0.0
        assert reward == pytest.approx(plain_reward + info["reward_metrics"], rel=1e-12)
        terms.append(-info["reward_metrics"])
    assert env.episode is not None
    metrics = compute_metrics(replace(env.episode.trace(), measured_pose=None))
    total = metrics.translation_error_pct + metrics.angle_error_pct
    assert np.mean(terms) == pytest.approx(total, rel=1e-9)


@pytest.mark.parametrize("plant", ["sim", "proxy"])
def test_the_gate_reads_the_deviation_of_the_pose_error_it_observes(plant: str) -> None:
    """The deviation is kept with the pose error (PushEnv._set_error): after every step it is
    hypot(e_x, e_y, gate_length · e_θ) of the observation's error, the camera's on the proxy,
    to the bit; the info's is the one the step's gate read, and the pose term the true one's."""
    config = replace(SHORT, plant=plant, w_pose=20.0, action_repeat=3)
    env = PushEnv(config)
    obs, _ = env.reset(options=OPTIONS)
    where = index(env.observation_entries)
    error_rows = [where[name] for name in ERROR_NAMES]
    rng = np.random.default_rng(4)
    for _ in range(12):
        e_x, e_y, e_w = env.pose_error.tolist()
        deviation = math.hypot(e_x, e_y, config.gate_length * e_w)
        assert env.gate_open == (deviation > config.gate_threshold)
        np.testing.assert_array_equal(obs[error_rows], env.pose_error.astype(np.float32))
        obs, _, _, _, info = env.step(rng.uniform(-1, 1, 3))
        assert info["pose_deviation"] == deviation
        assert info["reward_pose"] < 0.0


def test_a_shut_gate_leaves_the_pd_baseline_untouched() -> None:
    env = PushEnv(replace(SHORT, gate_threshold=1.0))
    env.reset(options=OPTIONS)
    for _ in range(200):
        _, _, terminated, _, info = env.step(np.ones(3))
        assert not info["residual_active"]
    assert terminated
    assert env.episode is not None
    with_residual = env.episode.trace()
    baseline = Episode(env.scenario, env.gains, plan=env.plan).run()
    np.testing.assert_array_equal(with_residual.object_pose, baseline.object_pose)
    np.testing.assert_array_equal(with_residual.contact_forces, baseline.contact_forces)


@pytest.mark.parametrize("plant", ["sim", "proxy"])
def test_finishing_with_a_policy_is_step_after_step_with_the_actor_only_behind_an_open_gate(
    plant: str,
) -> None:
    """finish_with_policy (advance, and the actor only while the gate is open) gives the
    step() loop's push to the bit, the proxy's force noise included."""
    calls: list[int] = []

    def actor(obs: np.ndarray) -> np.ndarray:
        assert env.episode is not None
        calls.append(env.episode.step_index)
        return np.array([1.0, -0.5, 0.2]) * math.cos(1e3 * float(obs.sum()))

    # Shut at the start (the placement error of this seed is 2-3 mm; on the proxy the gate
    # reads the camera, σ = 1 mm), open once the push falls behind its 2 s plan.
    config = replace(SHORT, plant=plant, gate_threshold=5e-3)
    env = PushEnv(config)
    obs, _ = env.reset(options=OPTIONS)
    opened = []
    for n in range(200):
        about_to_open = env.gate_open
        obs, _, _, _, info = env.step(actor(np.asarray(obs, dtype=np.float64)))
        assert info["residual_active"] == about_to_open
        opened += [n] if about_to_open else []
    assert env.episode is not None
    stepped = env.episode.trace()
    assert 0 < len(opened) < 200  # the threshold lets some steps through, not all

    calls.clear()
    env.reset(options=OPTIONS)
    assert finish_with_policy(env, actor) == len(opened)
    assert calls == opened
    assert env.episode is not None
    finished = env.episode.trace()
    np.testing.assert_array_equal(finished.object_pose, stepped.object_pose)
    np.testing.assert_array_equal(finished.contact_forces, stepped.contact_forces)


def test_an_open_gate_shifts_the_pusher_by_the_residual_over_k_x() -> None:
    """On the ``velocity`` path (the paper's form) the residual adds to v_e = v_ff + K_x
    (x_des − x): a constant residual v moves the pusher v / K_x ahead of its reference once
    the loop settles (time constant 1 / K_x)."""
    env = PushEnv(replace(SHORT, gate_threshold=0.0, residual_path="velocity"))
    env.reset(options=OPTIONS)
    for _ in range(30):
        env.step(np.array([1.0, 0.0, 0.0]))
    assert env.episode is not None
    pushed = env.episode.trace()
    baseline = Episode(env.scenario, env.gains, plan=env.plan)
    baseline.reset()
    for _ in range(30):
        baseline.step()
    ahead = pushed.pusher_position[30] - baseline.trace().pusher_position[30]
    along, _ = _rotate_to(env.plan.trajectory.pose[0, 2], ahead[0], ahead[1])
    expected = SHORT.action_scale_linear / env.gains.kx_linear
    assert along == pytest.approx(expected, rel=0.1)


@pytest.mark.parametrize("path", ["reference", "velocity"])
def test_the_reference_path_keeps_the_offset_the_residual_built(path: str) -> None:
    """30 steps at the full action along the push, then 120 at zero: the ``reference`` path
    has moved the pusher and the object scale × 0.3 s ahead of PD-only's for good (the PD
    servoes the shifted reference); on the ``velocity`` path the shift decays to nothing."""
    config = replace(SHORT, duration=20.0, gate_threshold=0.0, residual_path=path)
    env = PushEnv(config)
    env.reset(options=OPTIONS)
    # without plant unknowns: the object sits square on the prongs and moves with them
    env.reset(options={"scenario": replace(env.scenario, unknowns=NO_UNKNOWNS)})
    assert env.episode is not None
    baseline = Episode(env.scenario, env.gains, plan=env.plan)
    baseline.reset()
    for n in range(150):
        env.step(np.array([1.0 if n < 30 else 0.0, 0.0, 0.0]))
        baseline.step()
    pushed, alone = env.episode.trace(), baseline.trace()
    yaw = env.plan.trajectory.pose[0, 2]
    built = config.action_scale_linear * 30 * config.dt  # 1.5 mm
    for quantity in ("pusher_position", "object_pose"):
        ahead = getattr(pushed, quantity)[150] - getattr(alone, quantity)[150]
        along, across = _rotate_to(yaw, ahead[0], ahead[1])
        if path == "reference":
            assert along == pytest.approx(built, rel=0.01)
            assert abs(across) < 0.01 * built
        else:
            assert abs(along) < 0.01 * built
    offset = env.episode.reference_offset
    expected = built * np.array([math.cos(yaw), math.sin(yaw), 0.0]) if path == "reference" else 0
    np.testing.assert_allclose(offset, expected, atol=1e-3 * built)  # the plan turns a little


def test_one_seed_draws_one_episode_and_another_seed_another() -> None:
    env = PushEnv(SHORT)
    first, _ = env.reset(seed=11)
    scenario = env.scenario
    again, _ = env.reset(seed=11)
    np.testing.assert_array_equal(first, again)
    assert env.scenario == scenario
    env.reset(seed=12)
    assert env.scenario != scenario


def test_reset_options_fix_the_draw(env: PushEnv) -> None:
    env.reset(seed=5, options=OPTIONS)
    assert (env.scenario.object, env.scenario.profile, env.scenario.seed) == (
        "wedge",
        "trapezoid",
        3,
    )
    assert env.scenario.true_parameters != env.scenario.nominal  # the sim plant is randomised


def test_the_known_answer_ranges_draw_the_nominal_plant_with_a_mounting_yaw_only() -> None:
    env = PushEnv(replace(SHORT, ranges="randomisation_known_answer"))
    yaws = []
    for seed in range(4):
        env.reset(options={**OPTIONS, "scenario_seed": seed})
        scenario = env.scenario
        assert scenario.true_parameters.mu_ground == scenario.nominal.mu_ground
        assert scenario.true_parameters.mu_contact == scenario.nominal.mu_contact
        unknowns = scenario.unknowns
        assert unknowns == replace(
            NO_UNKNOWNS,
            mount_yaw=unknowns.mount_yaw,
            prong_errors=unknowns.prong_errors,
            ground_seed=unknowns.ground_seed,
        )
        assert not any(v for pair in unknowns.prong_errors for v in pair)
        yaws.append(unknowns.mount_yaw)
    assert 0.0 < max(abs(y) for y in yaws) <= math.radians(1.0)
    # the default ranges draw the same goal for the seed, and every unknown
    default = PushEnv(SHORT)
    default.reset(options={**OPTIONS, "scenario_seed": 3})
    assert default.scenario.goal == env.scenario.goal
    assert default.scenario.unknowns.placement != (0.0, 0.0, 0.0)


def test_bad_input_is_refused_with_one_line_errors(env: PushEnv) -> None:
    fresh = PushEnv(SHORT)
    with pytest.raises(StateError, match="reset"):
        fresh.step(np.zeros(3))
    env.reset(options=OPTIONS)
    with pytest.raises(ConfigError, match="3 finite numbers"):
        env.step(np.array([0.0, np.nan, 0.0]))
    with pytest.raises(ConfigError, match="3 finite numbers"):
        env.step(np.zeros(2))
    for bad in (np.inf, -np.inf, np.nan):  # the float32 array's fast path, too
        with pytest.raises(ConfigError, match="3 finite numbers"):
            env.step(np.array([0.0, bad, 0.0], dtype=np.float32))
    env.step(np.array([1e308, 1e308, 0.0]))  # finite, accepted: only its sum overflows
    with pytest.raises(ConfigError, match="unknown reset option 'goal'"):
        env.reset(options={"goal": 1})


@pytest.mark.parametrize(
    ("values", "message"),
    [
        ({"objects": ["sphere"]}, "objects must be a non-empty list of cube, wedge"),
        ({"profiles": []}, "profiles must be a non-empty list"),
        ({"plant": "real"}, "plant must be one of sim, proxy"),
        ({"stream": "test"}, "stream must be one of"),
        ({"ranges": "mine"}, "ranges must be one of randomisation, randomisation_known_answer"),
        ({"action_scale_linear": 0.0}, "action_scale_linear must be a finite number > 0"),
        ({"gate_threshold": -1e-3}, "gate_threshold must be a finite number >= 0"),
        ({"w_torque": float("nan")}, "w_torque must be a finite number >= 0"),
        ({"w_force": 1.0}, r"\[env\] has unknown keys \['w_force'\]"),
    ],
)
def test_env_config_rejects_bad_values(values: dict, message: str) -> None:
    with pytest.raises(ConfigError, match=message):
        EnvConfig.from_mapping(values)


def test_env_config_round_trips_through_a_mapping() -> None:
    config = EnvConfig(objects=("cube",), w_pose=3.0)
    assert EnvConfig.from_mapping(config.to_dict()) == config


def test_the_docs_tables_are_the_code_tables() -> None:
    text = LEARNING_PAGE.read_text()
    assert markdown_table(observation_entries(2, reference_offset=True)) in text
    assert markdown_table(ACTION_ENTRIES) in text


def test_the_scaled_observation_is_of_order_one_over_pd_only_pushes() -> None:
    """Divided by its scales, every row that varies over PD-only pushes (a cube and a wedge
    trapezoid, with the offset and context rows) has a 95th percentile of |x| between 0.05
    and 10: no row reaches the networks a hundred times larger or smaller than another."""
    config = EnvConfig(observe_context=True, action_repeat=10)
    env = PushEnv(config)
    scale = np.array([entry.scale for entry in env.observation_entries])
    rows = []
    for obj in ("cube", "wedge"):
        obs, _ = env.reset(options={"object": obj, "profile": "trapezoid", "scenario_seed": 0})
        rows.append(obs)
        done = False
        while not done:
            obs, _, done, _, _ = env.step(np.zeros(3, dtype=np.float32))
            rows.append(obs)
    scaled = np.abs(np.array(rows, dtype=float) / scale)
    varies = scaled.max(axis=0) > scaled.min(axis=0)
    names = [entry.name for entry in env.observation_entries]
    p95 = dict(zip(names, np.percentile(scaled, 95, axis=0), strict=True))
    outside = {
        name: round(float(p), 3)
        for (name, p), moves in zip(p95.items(), varies, strict=True)
        if moves and not 0.05 <= p <= 10.0
    }
    assert outside == {}
