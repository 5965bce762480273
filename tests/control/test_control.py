"""Unit tests of the PD baseline's pieces: the compiled kernel against its numpy reference,
the IK's task/null-space split, torque clipping, the pusher references, the gains file and
the scenario's validation and random streams."""

import math

import numpy as np
import pytest
from pd_reference import reference_command

from pushctl.arm import ArmConfig, load_arm
from pushctl.config import PusherConfig
from pushctl.control import (
    PDController,
    PDGains,
    load_gains,
    minimum_jerk,
    push_reference,
)
from pushctl.control.gains import gains_toml
from pushctl.engines import make_world
from pushctl.episode import PhysicalParameters, Scenario, stream_rng
from pushctl.episode.scenario import TargetRanges
from pushctl.errors import ConfigError, StateError
from pushctl.objects import resolve_object
from pushctl.planning import ForceSettings, make_plan
from pushctl.types import PlanarPose

STIFF = PDGains(kp=0, kv=100, kx_linear=50, kx_angular=50)
DT = 0.01


@pytest.fixture(scope="module")
def world():
    return make_world("cube")


@pytest.fixture(scope="module")
def ready_terms(world):
    world.reset()
    return world.arm_terms, world.q.copy()


def pusher_yaw(rotation):
    return math.atan2(rotation[1, 0], rotation[0, 0])


# ------------------------------------------------------------ kernel vs reference


@pytest.mark.parametrize(
    "gains",
    [STIFF, PDGains(), PDGains(kp=500, kv=5, kx_linear=5, kx_angular=20, posture_gain=3.0)],
    ids=["stiff", "default", "mixed"],
)
def test_compiled_kernel_equals_numpy_reference(world, gains):
    """On random arm states (q within the limits), desired poses near the pusher, random
    feed-forward twists, with and without a residual, both forms agree to 1e-10."""
    arm = world.arm
    controller = PDController(arm, gains, DT)
    rng = np.random.default_rng(20240611)
    saturated_seen = {True: 0, False: 0}
    for k in range(120):
        if k % 4 < 2:  # anywhere within the limits (mostly saturated: the pusher is tilted)
            q = rng.uniform(arm.q_lower, arm.q_upper)
        else:  # near the ready pose, where the pusher is level and small errors stay linear
            q = arm.q_ready + rng.uniform(-1.0, 1.0, arm.nq) * 10.0 ** rng.uniform(-6.0, -3.0)
        v = rng.uniform(-0.5, 0.5, arm.nv)
        world.reset(object_pose=(3.0, 3.0, 0.0), arm_q=q, arm_v=v)
        terms = world.arm_terms
        scale = 10.0 ** rng.uniform(-6.0, -1.3)  # errors from 1 µm (unsaturated) to 5 cm
        position_des = terms.pusher_position + rng.uniform(-scale, scale, 3)
        yaw_des = pusher_yaw(terms.pusher_rotation) + rng.uniform(-6 * scale, 6 * scale)
        twist_ff = rng.uniform(-scale, scale, 6)
        residual = None if k % 2 else rng.uniform(-scale, scale, 3)
        fast = controller.command(terms, world.q, position_des, yaw_des, twist_ff, residual)
        slow = reference_command(
            controller, terms, world.q, position_des, yaw_des, twist_ff, residual
        )
        for name in ("tau", "q_dot_des", "twist"):
            np.testing.assert_allclose(
                getattr(fast, name), getattr(slow, name), rtol=1e-10, atol=1e-10, err_msg=name
            )
        assert fast.saturated == slow.saturated
        assert fast.implicit_kv == slow.implicit_kv == gains.kv
        saturated_seen[fast.saturated] += 1
    # The sample covers both branches of the law (velocity/torque scaling or not).
    assert saturated_seen[True] > 0 and saturated_seen[False] > 0
    world.reset()


# ------------------------------------------------------------ the IK law at the ready pose


def test_zero_error_is_pure_gravity_compensation(ready_terms, world):
    terms, q = ready_terms
    controller = PDController(world.arm, STIFF, DT)
    cmd = controller.command(
        terms, q, terms.pusher_position.copy(), pusher_yaw(terms.pusher_rotation), np.zeros(6)
    )
    np.testing.assert_allclose(cmd.tau, terms.g, rtol=0, atol=1e-9)
    np.testing.assert_allclose(cmd.q_dot_des, 0.0, atol=1e-10)
    np.testing.assert_allclose(cmd.twist, 0.0, atol=1e-12)
    assert not cmd.saturated


def test_feed_forward_twist_is_tracked_by_damped_pinv(ready_terms, world):
    terms, q = ready_terms
    cond = np.linalg.cond(terms.pusher_jacobian)
    assert 5.0 < cond < 20.0  # the ready pose is well conditioned (cond J ≈ 11)
    controller = PDController(world.arm, STIFF, DT)
    rng = np.random.default_rng(3)
    for _ in range(10):
        twist = np.concatenate([rng.uniform(-0.03, 0.03, 3), rng.uniform(-0.1, 0.1, 3)])
        cmd = controller.command(
            terms, q, terms.pusher_position.copy(), pusher_yaw(terms.pusher_rotation), twist
        )
        # no velocity scaling (torque clipping does not touch q̇_des)
        assert np.all(np.abs(cmd.q_dot_des) < world.arm.velocity_limit)
        achieved = terms.pusher_jacobian @ cmd.q_dot_des
        assert np.linalg.norm(achieved - twist) <= 1e-4 * np.linalg.norm(twist)


def test_posture_term_lives_in_the_null_space(world):
    """Away from the ready configuration (along the self-motion of the arm, so the pusher
    stays level) the posture pull changes q̇_des but not the pusher twist J q̇_des (up to the
    damping's λ²/σ² leak)."""
    arm = world.arm
    j_ready = arm.pusher_jacobian(arm.q_ready)
    null = np.linalg.svd(j_ready)[2][-1]  # the one redundant direction (the elbow)
    q = arm.q_ready + 0.1 * null
    world.reset(object_pose=(3.0, 3.0, 0.0), arm_q=q)
    terms = world.arm_terms
    position_des = terms.pusher_position + np.array([0.002, -0.001, 0.0])
    yaw_des = pusher_yaw(terms.pusher_rotation) + 0.01
    twist_ff = np.array([0.01, 0.0, 0.0, 0.0, 0.0, 0.02])
    commands = []
    for posture_gain in (0.0, 1.0, 4.0):
        gains = PDGains(kp=0, kv=10, kx_linear=50, kx_angular=50, posture_gain=posture_gain)
        cmd = PDController(arm, gains, DT).command(terms, q, position_des, yaw_des, twist_ff)
        assert np.all(np.abs(cmd.q_dot_des) < arm.velocity_limit)  # no velocity scaling
        commands.append(cmd)
    world.reset()
    j = terms.pusher_jacobian
    base = j @ commands[0].q_dot_des
    for cmd in commands[1:]:
        # the joint velocities really differ ...
        assert np.linalg.norm(cmd.q_dot_des - commands[0].q_dot_des) > 1e-2
        # ... the task velocity does not
        np.testing.assert_allclose(j @ cmd.q_dot_des, base, rtol=0, atol=1e-6)
    np.testing.assert_allclose(base, commands[0].twist, rtol=0, atol=1e-4 * np.abs(base).max())


def test_torque_is_clipped_to_the_limits(ready_terms, world):
    terms, q = ready_terms
    gains = PDGains(kp=1e6, kv=1e5, kx_linear=1e3, kx_angular=1e3)
    controller = PDController(world.arm, gains, DT)
    target = terms.pusher_position + np.array([0.05, 0.03, -0.02])
    cmd = controller.command(terms, q, target, 0.4, np.zeros(6))
    limit = world.arm.torque_limit
    assert cmd.saturated
    assert np.all(np.abs(cmd.tau) <= limit)
    assert np.any(np.isclose(np.abs(cmd.tau), limit))  # some joint is at its limit
    assert np.all(np.abs(cmd.q_dot_des) <= world.arm.velocity_limit * (1 + 1e-12))


@pytest.mark.parametrize("length", [2, 4])
def test_command_rejects_residual_of_wrong_length(ready_terms, world, length):
    terms, q = ready_terms
    controller = PDController(world.arm, STIFF, DT)
    backing = np.array([0.0, 0.0, 0.0, 0.5])  # a slice of it keeps any over-read in bounds
    with pytest.raises(StateError, match="residual"):
        controller.command(
            terms,
            q,
            terms.pusher_position.copy(),
            0.0,
            np.zeros(6),
            backing[:length],
        )


# ------------------------------------------------------------ references


def test_minimum_jerk_boundaries_and_velocity():
    start, end = np.array([0.3, 0.0, 0.06]), np.array([0.38, -0.04, 0.07])
    start_yaw, end_yaw = 0.1, -0.5
    duration = 2.0
    ref = minimum_jerk(start, start_yaw, end, end_yaw, duration, DT)
    assert len(ref) == round(duration / DT) + 1
    np.testing.assert_allclose(ref.position[0], start, atol=1e-15)
    np.testing.assert_allclose(ref.position[-1], end, atol=1e-15)
    assert ref.yaw[0] == pytest.approx(start_yaw, abs=1e-15)
    assert ref.yaw[-1] == pytest.approx(end_yaw, abs=1e-15)
    for velocity in (ref.linear_velocity, ref.yaw_rate):
        np.testing.assert_array_equal(velocity[0], 0.0)
        np.testing.assert_array_equal(velocity[-1], 0.0)
    assert np.abs(ref.linear_velocity).max() > 0.01  # it does move in between
    displacement = np.trapezoid(ref.linear_velocity, dx=DT, axis=0)
    delta = end - start
    assert np.linalg.norm(displacement - delta) <= 1e-3 * np.linalg.norm(delta)
    turned = np.trapezoid(ref.yaw_rate, dx=DT)
    assert abs(turned - (end_yaw - start_yaw)) <= 1e-3 * abs(end_yaw - start_yaw)
    twist = ref.twist
    assert twist.shape == (len(ref), 6)
    np.testing.assert_array_equal(twist[:, 5], ref.yaw_rate)
    np.testing.assert_array_equal(twist[:, 3:5], 0.0)


@pytest.mark.parametrize("duration, dt", [(0.0, DT), (-1.0, DT), (1.0, 0.0), (math.nan, DT)])
def test_minimum_jerk_rejects_bad_times(duration, dt):
    with pytest.raises(ConfigError):
        minimum_jerk(np.zeros(3), 0.0, np.ones(3), 0.0, duration, dt)


@pytest.fixture(scope="module")
def planning_arm():
    return load_arm(ArmConfig(name="kinova-gen2-7dof", pusher=PusherConfig(mass=0.03)))


@pytest.mark.parametrize(
    "object_name, profile, goal",
    [
        ("cube", "constant", (0.60, 0.03, math.radians(30))),
        ("cube", "trapezoid", (0.60, 0.03, math.radians(30))),
        ("wedge", "chirp", (0.60, -0.03, math.radians(-30))),
    ],
)
def test_push_reference_velocity_is_the_derivative_of_its_path(
    planning_arm, object_name, profile, goal
):
    obj = resolve_object(object_name)
    plan = make_plan(obj, goal, profile=profile, arm=planning_arm, forces=ForceSettings())
    ref = push_reference(plan)
    dt = ref.dt
    np.testing.assert_array_equal(ref.position, plan.pusher_positions)
    np.testing.assert_array_equal(ref.yaw, plan.pusher_yaws)
    central = (ref.position[2:] - ref.position[:-2]) / (2 * dt)
    speed = np.linalg.norm(ref.linear_velocity, axis=1).max()
    assert speed > 1e-3
    assert np.abs(central - ref.linear_velocity[1:-1]).max() <= 2e-3 * speed
    yaw_rate = (ref.yaw[2:] - ref.yaw[:-2]) / (2 * dt)
    assert np.abs(yaw_rate - ref.yaw_rate[1:-1]).max() <= 2e-3 * np.abs(ref.yaw_rate).max()
    assert np.all(ref.linear_velocity[:, 2] == 0.0)  # the pusher stays at its height


# ------------------------------------------------------------ gains


@pytest.mark.parametrize(
    "kwargs",
    [
        {"kp": -1.0},
        {"kv": -20.0},
        {"kv": 0.0},
        {"kx_linear": math.nan},
        {"kx_angular": math.inf},
        {"ik_damping": "1e-3"},
        {"posture_gain": None},
        {"kp": True},
        {"kv": [20.0]},
    ],
)
def test_pd_gains_reject_bad_values(kwargs):
    with pytest.raises(ConfigError) as info:
        PDGains(**kwargs)
    message = str(info.value)
    assert "\n" not in message
    assert next(iter(kwargs)) in message


def test_pd_gains_accept_ints_as_floats():
    gains = PDGains(kp=1, kv=2, kx_linear=3, kx_angular=4, ik_damping=0, posture_gain=0)
    assert all(isinstance(value, float) for value in gains.as_dict().values())


GOOD_PD = "kp = 1.0\nkv = 2.0\nkx_linear = 3.0\nkx_angular = 4.0\nik_damping = 0.001\n"
GOOD_PD += "posture_gain = 0.5\n"


@pytest.mark.parametrize(
    "name, text, fragment",
    [
        ("missing.toml", None, "does not exist"),
        ("corrupt.toml", "[pd]\nkp = = 1\n", "cannot read"),
        ("no_pd.toml", "[search]\nseed = 1\n", "no [pd] table"),
        ("pd_not_table.toml", "pd = 3\n", "no [pd] table"),
        ("unknown.toml", "[pd]\n" + GOOD_PD + "ki = 0.1\n", "unknown keys ['ki']"),
        ("missing_key.toml", "[pd]\n" + GOOD_PD.replace("kv = 2.0\n", ""), "missing keys"),
        ("bad_value.toml", "[pd]\n" + GOOD_PD.replace("kp = 1.0", "kp = -1.0"), "kp"),
        ("string_value.toml", "[pd]\n" + GOOD_PD.replace("kp = 1.0", 'kp = "a"'), "kp"),
        ("binary.toml", b"\xff\xfe[pd]", "cannot read"),
    ],
)
def test_load_gains_errors_name_the_file(tmp_path, name, text, fragment):
    path = tmp_path / name
    if isinstance(text, bytes):
        path.write_bytes(text)
    elif text is not None:
        path.write_text(text, encoding="utf-8")
    with pytest.raises(ConfigError) as info:
        load_gains(path)
    message = str(info.value)
    assert str(path) in message
    assert fragment in message
    assert "\n" not in message


def test_load_gains_reads_a_good_file(tmp_path):
    path = tmp_path / "good.toml"
    path.write_text("# header\n[pd]\n" + GOOD_PD + "\n[search]\nseeds = [1, 2]\n")
    assert load_gains(str(path)) == PDGains(1.0, 2.0, 3.0, 4.0, 0.001, 0.5)


def test_gains_toml_round_trips(tmp_path):
    gains = PDGains(kp=123.456, kv=7.0 / 3.0, kx_linear=1e-7, kx_angular=55, posture_gain=0)
    search = {
        "method": 'grid "coarse" \\ fine',
        "seeds": [1, 2, 3],
        "scores": [0.5, 1e-9],
        "refined": True,
        "budget": 12,
    }
    text = gains_toml(gains, "tuned by a test\nsecond line", search)
    assert text.startswith("# tuned by a test\n# second line\n")
    path = tmp_path / "pd_gains.toml"
    path.write_text(text, encoding="utf-8")
    assert load_gains(path) == gains
    try:
        import tomllib
    except ModuleNotFoundError:  # Python 3.10
        import tomli as tomllib
    assert tomllib.loads(text)["search"] == search


# ------------------------------------------------------------ scenario and streams


GOAL = PlanarPose(0.6, 0.0, 0.0)


@pytest.mark.parametrize(
    "make",
    [
        lambda: Scenario(object="cube", profile="sinusoid", goal=GOAL),
        lambda: Scenario(object="cube", profile="constant", goal=GOAL, duration=0.0),
        lambda: Scenario(object="cube", profile="constant", goal=GOAL, dt=-0.01),
        lambda: Scenario(object="cube", profile="constant", goal=GOAL, duration=math.nan),
        lambda: PhysicalParameters(mu_ground=-0.1),
        lambda: PhysicalParameters(mu_contact=-0.4),
        lambda: PhysicalParameters(mu_contact=math.inf),
        lambda: PhysicalParameters(mu_ground="0.3"),
        lambda: PhysicalParameters(object_mass=0.0),
        lambda: PhysicalParameters(object_mass=-0.3),
        lambda: PhysicalParameters(pusher_mass=0.0),
        lambda: PhysicalParameters(pusher_mass=math.nan),
        lambda: TargetRanges(forward=(0.25, 0.10)),
        lambda: TargetRanges(forward=(-0.1, 0.1)),
        lambda: TargetRanges(rotation_deg=(10.0, 200.0)),
        lambda: TargetRanges(lateral=(0.0, math.nan)),
        lambda: TargetRanges(lateral=(0.0,)),
        lambda: TargetRanges(forward="ab"),
        lambda: stream_rng(-1, "tuning"),
        lambda: stream_rng(1.5, "tuning"),
        lambda: stream_rng(True, "tuning"),
        lambda: stream_rng("3", "tuning"),
        lambda: stream_rng(3, "testing"),
    ],
)
def test_scenario_validation(make):
    with pytest.raises(ConfigError) as info:
        make()
    assert "\n" not in str(info.value)


def test_streams_are_independent_and_reproducible():
    tuning = stream_rng(7, "tuning").uniform(size=8)
    evaluation = stream_rng(7, "evaluation").uniform(size=8)
    training = stream_rng(7, "training").uniform(size=8)
    assert not np.allclose(tuning, evaluation)
    assert not np.allclose(tuning, training)
    assert not np.allclose(evaluation, training)
    np.testing.assert_array_equal(stream_rng(7, "tuning").uniform(size=8), tuning)
    np.testing.assert_array_equal(stream_rng(np.int64(7), "tuning").uniform(size=8), tuning)
    assert not np.allclose(stream_rng(8, "tuning").uniform(size=8), tuning)


@pytest.mark.parametrize("start", [PlanarPose(0.42, 0.0, 0.0), PlanarPose(0.40, 0.1, 0.6)])
def test_target_ranges_draw_inside_documented_ranges(start):
    ranges = TargetRanges()
    rng = stream_rng(0, "evaluation")
    signs = set()
    forwards, laterals, rotations = [], [], []
    for _ in range(2000):
        goal = ranges.draw(rng, start)
        dx, dy = goal.x - start.x, goal.y - start.y
        c, s = math.cos(start.theta), math.sin(start.theta)
        forward, lateral = c * dx + s * dy, -s * dx + c * dy
        dtheta = goal.theta - start.theta
        sign = math.copysign(1.0, dtheta)
        signs.add(sign)
        forwards.append(forward)
        rotations.append(abs(math.degrees(dtheta)))
        laterals.append(lateral * sign)
    eps = 1e-12
    assert 0.10 - eps <= min(forwards) and max(forwards) <= 0.25 + eps
    assert 10.0 - 1e-9 <= min(rotations) and max(rotations) <= 45.0 + 1e-9
    assert -eps <= min(laterals) and max(laterals) <= 0.05 + eps
    assert signs == {1.0, -1.0}
    # the draws fill the ranges rather than sitting in a corner
    assert min(forwards) < 0.11 and max(forwards) > 0.24
    assert min(rotations) < 12.0 and max(rotations) > 43.0
    assert min(laterals) < 0.005 and max(laterals) > 0.045
