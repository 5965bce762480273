"""The ICR arc (docs/design.md §4): end points, the instant centre, rigid rotation of the whole
body about it, arc length, analytic derivatives against finite differences, the straight
limit Δθ → 0, the push angle and input validation."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pushctl.errors import ConfigError
from pushctl.planning.trajectory import instant_centre, plan_icr
from pushctl.types import PlanarPose

EPS = np.finfo(float).eps
TINY_ROTATIONS = [1e-10, -1e-10, 1e-7, -1e-7, 1e-4, -1e-4]

coordinate = st.floats(-0.5, 0.5)
rotation = st.one_of(
    st.floats(-math.pi, math.pi, exclude_min=True),
    st.sampled_from([*TINY_ROTATIONS, 0.0, math.pi]),
)
heading = st.floats(-math.pi, math.pi)


@st.composite
def start_goal(draw, zero_heading=False):
    theta0 = 0.0 if zero_heading else draw(heading)
    start = PlanarPose(draw(coordinate), draw(coordinate), theta0)
    goal = PlanarPose(draw(coordinate), draw(coordinate), theta0 + draw(rotation))
    return start, goal


def rot(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s], [s, c]])


def wrap(angle):
    return np.remainder(np.asarray(angle) + math.pi, 2 * math.pi) - math.pi


def third_difference_bound(values: np.ndarray, step: float) -> float:
    """max |f'''| over the samples (rows), estimated from third differences, ×2 margin."""
    return 2.0 * float(np.abs(np.diff(values, 3, axis=0)).max(initial=0.0)) / step**3


def assert_all_finite(tr):
    for name in ("t", "s", "pose", "velocity", "acceleration", "path_tangent"):
        assert np.all(np.isfinite(getattr(tr, name))), name
    assert math.isfinite(tr.arc_length)
    assert tr.icr is None or np.all(np.isfinite(tr.icr))


# ------------------------------------------------------------------ geometry


@settings(max_examples=150, deadline=None)
@given(pair=start_goal(), profile=st.sampled_from(["constant", "trapezoid", "chirp"]))
def test_end_points_theta_and_sampling(pair, profile):
    start, goal = pair
    tr = plan_icr(start, goal, duration=2.0, dt=0.02, profile=profile)
    assert_all_finite(tr)
    assert tr.n_steps == 100 and tr.pose.shape == (101, 3)
    np.testing.assert_allclose(tr.t, 0.02 * np.arange(101), rtol=0, atol=1e-15)
    np.testing.assert_allclose(tr.pose[0], start.as_array(), rtol=0, atol=1e-12)
    np.testing.assert_allclose(tr.pose[-1], goal.as_array(), rtol=0, atol=1e-12)
    assert tr.s[0] == pytest.approx(0.0, abs=1e-12) and tr.s[-1] == pytest.approx(1.0, abs=1e-12)
    # θ is linear in the arc fraction s
    np.testing.assert_allclose(
        tr.pose[:, 2], start.theta + tr.delta_theta * tr.s, rtol=0, atol=1e-12
    )
    assert -math.pi < tr.delta_theta <= math.pi + 1e-12


@settings(max_examples=150, deadline=None)
@given(pair=start_goal())
def test_instant_centre_rotates_start_onto_goal(pair):
    start, goal = pair
    tr = plan_icr(start, goal, duration=1.0, dt=0.01)
    delta = tr.delta_theta
    p0, p1 = start.as_array()[:2], goal.as_array()[:2]
    if abs(delta) < 1e-9:
        assert tr.icr is None and instant_centre(start, goal) is None
        assert tr.radius == math.inf
        return
    c = tr.icr
    assert c is not None
    np.testing.assert_array_equal(c, instant_centre(start, goal))
    scale = float(np.linalg.norm(p0 - c))
    tol = 1e-12 + 16 * EPS * scale
    np.testing.assert_allclose(rot(delta) @ (p0 - c) + c, p1, rtol=0, atol=tol)
    # c lies on the perpendicular bisector of p0 p1 (it is equidistant from both)
    d = p1 - p0
    assert abs((c - 0.5 * (p0 + p1)) @ d) <= 1e-12 + 1e-12 * scale * np.linalg.norm(d)
    # independently: c solves (I − R) c = p1 − R p0; that solve loses digits like 1/|Δθ|
    # (at Δθ = 3.6e-9 it misplaces c by 0.25 m across the bisector), so only where it is
    # well conditioned
    if abs(delta) > 1e-3:
        expected = np.linalg.solve(np.eye(2) - rot(delta), p1 - rot(delta) @ p0)
        ref_tol = 1e-12 + 1e-9 * scale + 8 * EPS * (1.0 + np.abs(p0).sum()) / abs(delta)
        np.testing.assert_allclose(c, expected, rtol=0, atol=ref_tol)
    # the centre of mass stays on the circle about c through p0 and p1
    distances = np.linalg.norm(tr.pose[:, :2] - c, axis=1)
    np.testing.assert_allclose(distances, tr.radius, rtol=1e-9, atol=1e-12)
    assert tr.radius == pytest.approx(scale, rel=1e-9, abs=1e-12)


@settings(max_examples=150, deadline=None)
@given(
    pair=start_goal(),
    body_point=st.tuples(st.floats(-0.1, 0.1), st.floats(-0.1, 0.1)),
    profile=st.sampled_from(["constant", "chirp"]),
)
def test_every_point_of_the_body_rotates_about_the_icr(pair, body_point, profile):
    start, goal = pair
    tr = plan_icr(start, goal, duration=1.0, dt=0.01, profile=profile)
    if tr.icr is None:
        return
    omega = tr.velocity[:, 2]
    for local in (np.zeros(2), np.array(body_point)):
        # the point's world position and velocity v + ω × r
        r = np.array([rot(th) @ local for th in tr.pose[:, 2]])
        q = tr.pose[:, :2] + r
        v = tr.velocity[:, :2] + omega[:, None] * np.column_stack([-r[:, 1], r[:, 0]])
        arm = q - tr.icr
        arm_len = np.linalg.norm(arm, axis=1)
        speed = np.linalg.norm(v, axis=1)
        # |v| = |ω| |q − c|
        np.testing.assert_allclose(speed, np.abs(omega) * arm_len, rtol=1e-9, atol=1e-12)
        # v ⟂ (q − c)
        moving = (speed > 1e-12) & (arm_len > 1e-12)
        cosine = np.einsum("ij,ij->i", v, arm)[moving] / (speed * arm_len)[moving]
        assert np.abs(cosine).max(initial=0.0) < 1e-9


@settings(max_examples=60, deadline=None)
@given(pair=start_goal())
def test_arc_length_is_radius_times_angle_and_the_polyline_length(pair):
    start, goal = pair
    tr = plan_icr(start, goal, duration=2.0, dt=0.001)  # 2000 evenly spaced samples
    d = float(np.linalg.norm(tr.displacement))
    if tr.icr is not None:
        assert tr.arc_length == pytest.approx(tr.radius * abs(tr.delta_theta), rel=1e-9, abs=1e-15)
    else:
        assert tr.arc_length == pytest.approx(d, rel=1e-12, abs=1e-15)
    polyline = float(np.linalg.norm(np.diff(tr.pose[:, :2], axis=0), axis=1).sum())
    # (abs: 2000 segments of rounding noise, eps·|p| each, when |d| is at the femtometre scale)
    assert polyline == pytest.approx(tr.arc_length, rel=1e-5, abs=1e-12)
    assert tr.arc_length >= d - 1e-15  # an arc is never shorter than its chord


def test_half_turn_arc_is_a_semicircle():
    start, goal = PlanarPose(0.0, 0.0, 0.0), PlanarPose(0.2, 0.0, math.pi)
    tr = plan_icr(start, goal, 1.0, 0.01)
    np.testing.assert_allclose(tr.icr, [0.1, 0.0], atol=1e-15)
    assert tr.radius == pytest.approx(0.1, rel=1e-14)
    assert tr.arc_length == pytest.approx(0.1 * math.pi, rel=1e-14)
    # counter-clockwise about c from (0, 0) to (0.2, 0) passes below: y = −0.1 halfway
    np.testing.assert_allclose(tr.pose[50], [0.1, -0.1, math.pi / 2], atol=1e-14)


# --------------------------------------------------------------- derivatives


@settings(max_examples=40, deadline=None)
@given(pair=start_goal(), profile=st.sampled_from(["constant", "chirp"]))
def test_velocity_and_acceleration_are_derivatives(pair, profile):
    start, goal = pair
    dt = 1e-3
    tr = plan_icr(start, goal, duration=1.0, dt=dt, profile=profile)
    pose, vel, acc = tr.pose, tr.velocity, tr.acceleration
    fd_vel = (pose[2:] - pose[:-2]) / (2 * dt)
    fd_acc = (vel[2:] - vel[:-2]) / (2 * dt)
    # central differences are exact up to dt²/6·|f'''|, f''' estimated from the samples of f
    tol_v = 1e-10 + dt**2 * third_difference_bound(pose, dt) / 3
    tol_a = 1e-10 + dt**2 * third_difference_bound(vel, dt) / 3
    np.testing.assert_allclose(fd_vel, vel[1:-1], rtol=0, atol=tol_v)
    np.testing.assert_allclose(fd_acc, acc[1:-1], rtol=0, atol=tol_a)
    # these tolerances are small against the signals themselves
    scale_v, scale_a = np.abs(vel).max(), np.abs(acc).max()
    assert tol_v <= 1e-9 + 1e-3 * scale_v
    assert tol_a <= 1e-9 + 1e-2 * scale_a
    # the tangent dp/ds times ṡ is the velocity (ṡ = ω/Δθ), and ṡ = 1/T for constant
    if profile == "constant":
        np.testing.assert_allclose(tr.path_tangent, vel[:, :2] * 1.0, rtol=1e-12, atol=1e-15)
    elif abs(tr.delta_theta) > 1e-3:
        s_dot = vel[:, 2] / tr.delta_theta
        np.testing.assert_allclose(
            tr.path_tangent * s_dot[:, None], vel[:, :2], rtol=1e-12, atol=1e-14
        )


def test_trapezoid_starts_and_ends_at_rest_but_knows_its_direction():
    start, goal = PlanarPose(0.42, 0.0, 0.0), PlanarPose(0.62, 0.03, 0.5)
    tr = plan_icr(start, goal, 20.0, 0.01, "trapezoid")
    np.testing.assert_allclose(tr.velocity[[0, -1]], 0.0, atol=1e-15)
    # the direction of motion is defined at rest: the tangent at the ends
    assert np.linalg.norm(tr.path_tangent[0]) > 0.1
    expected = tr.displacement / math.sin(0.25) * 0.25  # |p'| = |d| / sinc(Δθ/2)
    assert np.linalg.norm(tr.path_tangent[0]) == pytest.approx(np.linalg.norm(expected))


# -------------------------------------------------------------- straight limit


def straight_and_turned(d, delta, theta0=0.3, profile="constant"):
    start = PlanarPose(0.1, -0.2, theta0)
    straight = plan_icr(start, PlanarPose(0.1 + d[0], -0.2 + d[1], theta0), 1.0, 0.01, profile)
    turned = plan_icr(
        start, PlanarPose(0.1 + d[0], -0.2 + d[1], theta0 + delta), 1.0, 0.01, profile
    )
    return straight, turned


@settings(max_examples=60, deadline=None)
@given(
    d=st.tuples(st.floats(-0.5, 0.5), st.floats(-0.5, 0.5)),
    sign=st.sampled_from([-1.0, 1.0]),
    profile=st.sampled_from(["constant", "chirp"]),
)
def test_tiny_rotations_converge_to_the_straight_plan(d, sign, profile):
    length = math.hypot(*d)
    for delta, tol in ((1e-9, 2e-9), (1e-6, 1e-6)):
        straight, turned = straight_and_turned(d, sign * delta, profile=profile)
        assert straight.icr is None and straight.radius == math.inf
        assert_all_finite(turned)
        assert_all_finite(straight)
        v_max = float(np.linalg.norm(straight.velocity[:, :2], axis=1).max())
        a_max = float(np.linalg.norm(straight.acceleration[:, :2], axis=1).max())
        s_dot_max = v_max / max(length, 1e-300)
        # the arc's sagitta is |d| Δθ/8; its velocity turns by at most Δθ/2; its
        # acceleration adds the centripetal Δθ |d| ṡ² to a tangential part turned by Δθ/2
        np.testing.assert_allclose(
            turned.pose[:, :2], straight.pose[:, :2], rtol=0, atol=tol * length + 1e-15
        )
        np.testing.assert_allclose(turned.pose[:, 2], straight.pose[:, 2], rtol=0, atol=tol)
        np.testing.assert_allclose(
            turned.velocity[:, :2], straight.velocity[:, :2], rtol=0, atol=tol * v_max + 1e-15
        )
        np.testing.assert_allclose(
            turned.acceleration[:, :2],
            straight.acceleration[:, :2],
            rtol=0,
            atol=tol * (length * s_dot_max**2 + a_max) + 1e-15,
        )
        assert turned.arc_length == pytest.approx(straight.arc_length, rel=tol, abs=1e-15)


@pytest.mark.parametrize(
    "delta", [0.0, 5e-324, 1e-300, 1e-12, 1e-10, 9.999999999e-10, 1e-9, 1.0000001e-9, 1e-7]
)
@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_no_nan_or_inf_near_the_straight_limit(delta, sign):
    start = PlanarPose(0.42, 0.0, 0.0)
    goal = PlanarPose(0.62, 0.03, sign * delta)
    for profile in ("constant", "trapezoid", "chirp"):
        tr = plan_icr(start, goal, 20.0, 0.01, profile)
        assert_all_finite(tr)
        # ICR and radius agree on whether the plan is straight
        assert (tr.icr is None) == (tr.radius == math.inf)
        assert math.isfinite(tr.push_angle)
        np.testing.assert_allclose(tr.pose[-1], goal.as_array(), rtol=0, atol=1e-12)
        if tr.icr is not None:
            assert tr.radius == pytest.approx(np.linalg.norm(start.as_array()[:2] - tr.icr))


def test_straight_plan_is_a_line():
    start, goal = PlanarPose(0.42, 0.0, 0.2), PlanarPose(0.62, 0.05, 0.2)
    tr = plan_icr(start, goal, 1.0, 0.01, "chirp")
    assert tr.icr is None and tr.radius == math.inf and tr.delta_theta == 0.0
    d = tr.displacement
    np.testing.assert_allclose(tr.pose[:, :2], start.as_array()[:2] + tr.s[:, None] * d, atol=1e-15)
    np.testing.assert_array_equal(tr.velocity[:, 2], 0.0)
    assert tr.arc_length == pytest.approx(float(np.linalg.norm(d)), rel=1e-15)


# ---------------------------------------------------------------- push angle


@settings(max_examples=150, deadline=None)
@given(pair=start_goal(zero_heading=True))
def test_push_angle_formula_at_zero_heading(pair):
    start, goal = pair
    tr = plan_icr(start, goal, 1.0, 0.01)
    dx, dy = goal.x - start.x, goal.y - start.y
    if dx == 0.0 and dy == 0.0:
        assert math.isnan(tr.push_angle)
        return
    expected = math.atan2(dy, dx) - tr.delta_theta / 2
    assert wrap(tr.push_angle - expected) == pytest.approx(0.0, abs=1e-12)
    assert -math.pi <= tr.push_angle <= math.pi


@settings(max_examples=150, deadline=None)
@given(pair=start_goal(), profile=st.sampled_from(["constant", "trapezoid", "chirp"]))
def test_push_angle_is_constant_in_the_body_frame(pair, profile):
    start, goal = pair
    tr = plan_icr(start, goal, 1.0, 0.01, profile)
    if not np.any(tr.displacement):
        return
    # direction of motion relative to the body's e_n = (cos θ, sin θ), at every sample
    tangent_angle = np.arctan2(tr.path_tangent[:, 1], tr.path_tangent[:, 0]) - tr.pose[:, 2]
    np.testing.assert_allclose(wrap(tangent_angle - tr.push_angle), 0.0, atol=1e-9)
    moving = np.linalg.norm(tr.velocity[:, :2], axis=1) > 1e-9 * np.linalg.norm(tr.displacement)
    velocity_angle = np.arctan2(tr.velocity[moving, 1], tr.velocity[moving, 0])
    np.testing.assert_allclose(
        wrap(velocity_angle - tr.pose[moving, 2] - tr.push_angle), 0.0, atol=1e-9
    )


# ------------------------------------------------------------------ bad input


@pytest.mark.parametrize(
    ("duration", "dt"),
    [
        (0.0, 0.01),
        (-1.0, 0.01),
        (1.0, 0.0),
        (1.0, -0.01),
        (1.0, 0.3),
        (20.0, 0.03),
        (0.005, 0.01),
        (math.nan, 0.01),
        (1.0, math.nan),
        (math.inf, 0.01),
        (1.0, math.inf),
    ],
)
def test_bad_times_raise_config_error(duration, dt):
    with pytest.raises(ConfigError):
        plan_icr(PlanarPose(0, 0, 0), PlanarPose(0.1, 0, 0.1), duration, dt)


@pytest.mark.parametrize(
    ("start", "goal"),
    [
        (PlanarPose(0, 0, 0), PlanarPose(0.1, 0, 3.2)),
        (PlanarPose(0, 0, 0), PlanarPose(0.1, 0, -math.pi - 1e-6)),
        (PlanarPose(0, 0, -2.0), PlanarPose(0.1, 0, 2.0)),
        (PlanarPose(0, 0, 0), PlanarPose(math.nan, 0, 0.1)),
        (PlanarPose(0, math.nan, 0), PlanarPose(0.1, 0, 0.1)),
        (PlanarPose(0, 0, math.nan), PlanarPose(0.1, 0, 0.1)),
        (PlanarPose(0, 0, 0), PlanarPose(0.1, 0, math.inf)),
        (PlanarPose(0, 0, 0), PlanarPose(math.inf, 0, 0)),
    ],
)
def test_bad_poses_raise_config_error(start, goal):
    with pytest.raises(ConfigError):
        plan_icr(start, goal, 1.0, 0.01)


def test_half_turn_both_ways_is_accepted():
    for delta in (math.pi, -math.pi):
        tr = plan_icr(PlanarPose(0, 0, 0), PlanarPose(0.1, 0, delta), 1.0, 0.01)
        assert abs(tr.delta_theta) == pytest.approx(math.pi)
