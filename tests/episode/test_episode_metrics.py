"""Episode metrics (docs/design.md §7) on hand-built traces with known answers: each error and
fraction, row 0 excluded, the NaN angle percentage of a straight push, the slip test at the
friction cone's boundary, invalid inputs, and invariance of the translation error to a rigid
motion of both paths and to a common scaling of the paths and the arc length."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from pushctl.episode.metrics import METRIC_UNITS, EpisodeMetrics, compute_metrics
from pushctl.episode.trace import Trace
from pushctl.errors import ConfigError, StateError

K = 2  # prongs
NQ = 7  # arm joints


def make_trace(n: int, **overrides: object) -> Trace:
    """A trace of ``n`` push steps (n + 1 rows), 2 prongs, a 7-joint arm: zero poses and
    torques, both prongs pressing with (λ_n, λ_t) = (1, 0) N as planned, zero gaps,
    μ_c = 0.5, arc length 0.2 m, Δθ = 20°; ``overrides`` replaces any field."""
    rows = n + 1
    fields: dict[str, object] = {
        "t": np.arange(rows) * 0.01,
        "object_pose": np.zeros((rows, 3)),
        "desired_pose": np.zeros((rows, 3)),
        "contact_forces": np.tile([1.0, 0.0], (rows, K, 1)),
        "desired_forces": np.tile([1.0, 0.0], (rows, K, 1)),
        "plan_forces": np.tile([1.0, 0.0], (rows, K, 1)),
        "contact_torque": np.zeros(rows),
        "desired_torque": np.zeros(rows),
        "prong_gaps": np.zeros((rows, K)),
        "arm_q": np.zeros((rows, NQ)),
        "arm_v": np.zeros((rows, NQ)),
        "arm_tau": np.zeros((rows, NQ)),
        "pusher_position": np.zeros((rows, 3)),
        "pusher_position_des": np.zeros((rows, 3)),
        "mu_contact": 0.5,
        "arc_length": 0.2,
        "delta_theta": math.radians(20.0),
    }
    fields.update(overrides)
    return Trace(**fields)  # type: ignore[arg-type]


def test_perfect_push_has_zero_errors():
    m = compute_metrics(make_trace(10))
    assert m == EpisodeMetrics(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    assert math.isnan(compute_metrics(make_trace(10, plan_forces=None)).force_error_plan)


def test_force_error_plan_is_against_the_plan_s_forces_and_force_error_against_the_plant_s():
    planned = np.tile([1.3, 0.4], (4, K, 1))  # the nominal plan asked 0.5 N more
    m = compute_metrics(make_trace(3, plan_forces=planned))
    assert m.force_error == 0.0  # the plant needed what the prongs applied
    assert m.force_error_plan == pytest.approx(0.5)


def test_lateral_offset_of_5mm_on_a_02m_arc_is_2_5_percent():
    n = 20
    x = np.linspace(0.0, 0.2, n + 1)
    desired = np.column_stack([x, np.zeros(n + 1), np.zeros(n + 1)])
    actual = desired + [0.0, 0.005, 0.0]
    m = compute_metrics(make_trace(n, object_pose=actual, desired_pose=desired))
    assert m.translation_error_pct == pytest.approx(2.5)
    assert m.final_position_error == pytest.approx(0.005)
    assert m.angle_error_pct == 0.0


def test_one_degree_on_twenty_is_5_percent():
    n = 8
    theta_des = np.linspace(0.0, math.radians(20.0), n + 1)
    desired = np.column_stack([np.zeros(n + 1), np.zeros(n + 1), theta_des])
    actual = desired - [0.0, 0.0, math.radians(1.0)]  # the sign does not matter
    m = compute_metrics(make_trace(n, object_pose=actual, desired_pose=desired))
    assert m.angle_error_pct == pytest.approx(5.0)
    assert m.angle_error_deg == pytest.approx(1.0)
    assert m.final_angle_error == pytest.approx(math.radians(1.0))
    assert m.translation_error_pct == 0.0


def test_negative_delta_theta_uses_its_magnitude():
    pose = np.zeros((5, 3))
    pose[:, 2] = math.radians(1.0)
    m = compute_metrics(make_trace(4, object_pose=pose, delta_theta=-math.radians(20.0)))
    assert m.angle_error_pct == pytest.approx(5.0)


def test_straight_push_has_nan_angle_percent_but_degrees():
    pose = np.zeros((5, 3))
    pose[:, 2] = math.radians(2.0)
    m = compute_metrics(make_trace(4, object_pose=pose, delta_theta=0.0))
    assert math.isnan(m.angle_error_pct)
    assert m.angle_error_deg == pytest.approx(2.0)
    assert m.final_angle_error == pytest.approx(math.radians(2.0))


def test_zero_arc_length_gives_nan_translation_percent():
    m = compute_metrics(make_trace(3, arc_length=0.0))
    assert math.isnan(m.translation_error_pct)


def test_force_error_averages_over_steps_and_prongs():
    n = 6
    desired = np.tile([2.0, 0.5], (n + 1, K, 1))
    actual = desired.copy()
    actual[:, 0, :] -= [3.0, 4.0]  # ‖(3, 4)‖ = 5 N on prong 0, exact on prong 1
    m = compute_metrics(make_trace(n, contact_forces=actual, desired_forces=desired))
    assert m.force_error == pytest.approx(2.5)


def test_torque_error_of_alternating_differences():
    n = 10
    difference = 0.1 * (-1.0) ** np.arange(n + 1)
    desired = np.full(n + 1, 0.3)
    m = compute_metrics(make_trace(n, contact_torque=desired + difference, desired_torque=desired))
    assert m.torque_error == pytest.approx(0.1)


def test_contact_loss_fraction_counts_steps_with_any_prong_dropped():
    n = 10
    forces = np.tile([1.0, 0.0], (n + 1, K, 1))
    forces[[2, 3, 7], 1, 0] = 0.0  # prong 1 dropped on 3 steps
    forces[[3, 9], 0, 0] = 5e-4  # prong 0 below 1e-3 N on step 3 (already counted) and 9
    m = compute_metrics(make_trace(n, contact_forces=forces))
    assert m.contact_loss_fraction == 4 / n
    assert compute_metrics(make_trace(n, contact_forces=forces), 1e-4).contact_loss_fraction == (
        3 / n
    )


def test_slip_at_the_cone_counts_strictly_inside_does_not():
    n, mu = 4, 0.5
    forces = np.tile([2.0, 0.0], (n + 1, K, 1))
    forces[1, 0, 1] = mu * 2.0  # exactly on the cone
    forces[2, 1, 1] = -mu * 2.0 * (1.0 - 0.5e-3)  # within the tolerance of the boundary
    forces[3, 0, 1] = mu * 2.0 * 0.99  # strictly inside
    m = compute_metrics(make_trace(n, contact_forces=forces, mu_contact=mu))
    assert m.slip_fraction == 2 / n


def test_slip_needs_contact():
    n = 4
    forces = np.tile([1.0, 0.0], (n + 1, K, 1))
    forces[1:, 0] = [0.0, 0.0]  # prong 0 out of contact: 0 ≥ μ·0 is not a slip
    m = compute_metrics(make_trace(n, contact_forces=forces))
    assert m.slip_fraction == 0.0
    assert m.contact_loss_fraction == 1.0


def test_max_penetration_is_the_deepest_negative_gap():
    n = 5
    gaps = np.full((n + 1, K), 0.002)
    gaps[2, 0] = -1e-4
    gaps[4, 1] = -3e-4
    m = compute_metrics(make_trace(n, prong_gaps=gaps))
    assert m.max_penetration == pytest.approx(3e-4)
    assert compute_metrics(make_trace(n, prong_gaps=np.full((n + 1, K), 0.01))).max_penetration == 0


def test_row_zero_does_not_count():
    n = 5
    pose = np.zeros((n + 1, 3))
    pose[0] = [100.0, -100.0, 50.0]
    forces = np.tile([1.0, 0.0], (n + 1, K, 1))
    forces[0] = [[0.0, 1e3], [1e3, 1e3]]  # lost contact, slipping, huge force error
    torque = np.zeros(n + 1)
    torque[0] = 1e3
    gaps = np.zeros((n + 1, K))
    gaps[0] = -1.0
    trace = make_trace(
        n, object_pose=pose, contact_forces=forces, contact_torque=torque, prong_gaps=gaps
    )
    assert all(value == 0.0 for value in compute_metrics(trace).as_dict().values())


def test_final_errors_use_the_last_row():
    n = 3
    pose = np.zeros((n + 1, 3))
    pose[1] = [0.1, 0.0, 0.2]
    pose[-1] = [0.003, 0.004, -0.05]
    m = compute_metrics(make_trace(n, object_pose=pose))
    assert m.final_position_error == pytest.approx(0.005)
    assert m.final_angle_error == pytest.approx(0.05)


def test_no_push_steps_raises_state_error():
    with pytest.raises(StateError, match="at least 1 push step") as info:
        compute_metrics(make_trace(0))
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("threshold", [-1e-3, math.nan, math.inf])
def test_bad_threshold_raises_config_error(threshold):
    with pytest.raises(ConfigError, match="contact_threshold"):
        compute_metrics(make_trace(2), contact_threshold=threshold)


def test_as_dict_and_units_follow_the_field_order():
    m = compute_metrics(make_trace(3))
    names = [f.name for f in dataclasses.fields(EpisodeMetrics)]
    assert list(m.as_dict()) == names
    assert list(METRIC_UNITS) == names
    assert all(type(value) is float for value in m.as_dict().values())
    assert set(METRIC_UNITS.values()) == {"%", "N", "N·m", "1", "m", "rad", "deg"}


def test_metrics_are_frozen():
    m = compute_metrics(make_trace(1))
    with pytest.raises(dataclasses.FrozenInstanceError):
        m.force_error = 1.0  # type: ignore[misc]


def rotation(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s], [s, c]])


def paths(seed: int, n: int) -> tuple[np.ndarray, np.ndarray]:
    """A desired path and an actual one wandering a few mm around it, (n + 1, 3) each."""
    rng = np.random.default_rng(seed)
    desired = np.cumsum(rng.normal(0.0, 0.01, (n + 1, 3)), axis=0)
    return desired + rng.normal(0.0, 0.005, (n + 1, 3)), desired


def moved(pose: np.ndarray, angle: float, shift: np.ndarray) -> np.ndarray:
    """``pose`` (B, 3) under the rigid motion: rotate by ``angle`` about the origin, then
    translate by ``shift`` (2,)."""
    out = pose.copy()
    out[:, :2] = pose[:, :2] @ rotation(angle).T + shift
    out[:, 2] = pose[:, 2] + angle
    return out


@given(
    seed=st.integers(0, 2**32 - 1),
    n=st.integers(1, 30),
    angle=st.floats(-math.pi, math.pi),
    shift=st.tuples(st.floats(-2.0, 2.0), st.floats(-2.0, 2.0)),
)
def test_errors_are_invariant_to_a_rigid_motion_of_both_paths(seed, n, angle, shift):
    actual, desired = paths(seed, n)
    before = compute_metrics(make_trace(n, object_pose=actual, desired_pose=desired))
    offset = np.array(shift)
    after = compute_metrics(
        make_trace(
            n,
            object_pose=moved(actual, angle, offset),
            desired_pose=moved(desired, angle, offset),
        )
    )
    for name in ("translation_error_pct", "final_position_error"):
        assert getattr(after, name) == pytest.approx(getattr(before, name), rel=1e-9, abs=1e-12)
    for name in ("angle_error_pct", "angle_error_deg", "final_angle_error"):
        assert getattr(after, name) == pytest.approx(getattr(before, name), rel=1e-9, abs=1e-9)


@given(
    seed=st.integers(0, 2**32 - 1),
    n=st.integers(1, 30),
    scale=st.floats(1e-3, 1e3),
)
def test_translation_percent_is_invariant_to_scaling_paths_and_arc(seed, n, scale):
    actual, desired = paths(seed, n)
    before = compute_metrics(make_trace(n, object_pose=actual, desired_pose=desired))
    xy = np.array([scale, scale, 1.0])
    after = compute_metrics(
        make_trace(n, object_pose=actual * xy, desired_pose=desired * xy, arc_length=0.2 * scale)
    )
    assert after.translation_error_pct == pytest.approx(before.translation_error_pct, rel=1e-9)
    assert after.final_position_error == pytest.approx(scale * before.final_position_error)
