"""The compiled arm terms (pushctl.native) against Pinocchio's Python bindings, to the bit.

The library is built by the Makefile's install; CI (.ci/run) sets PUSHCTL_EXPECT_NATIVE=1,
so there a missing or stale library fails instead of skipping (tests/native/conftest.py).
"""

from __future__ import annotations

import copy
import pickle
from dataclasses import replace

import numpy as np
import pytest

from pushctl.arm import ArmConfig, ArmModel, ArmTerms, load_arm
from pushctl.config import PusherConfig
from pushctl.engines import make_world


def _through_bindings(arm: ArmModel, q: np.ndarray, v: np.ndarray) -> ArmTerms:
    """ArmModel.compute with the library turned off for this model."""
    kept = arm._native
    arm._native = False
    try:
        return arm.compute(q, v)
    finally:
        arm._native = kept


def _random_states(arm: ArmModel, n: int, seed: int):
    rng = np.random.default_rng(seed)
    lower = np.maximum(arm.q_lower, -np.pi)
    upper = np.minimum(arm.q_upper, np.pi)
    for _ in range(n):
        yield rng.uniform(lower, upper), rng.normal(0.0, 1.5, arm.nv)


def _assert_same_bits(a: ArmTerms, b: ArmTerms) -> None:
    for name, x, y in zip(ArmTerms._fields, a, b, strict=True):
        assert x.shape == y.shape and x.dtype == y.dtype, name
        assert x.tobytes() == y.tobytes(), name


def test_terms_match_the_bindings_bit_for_bit():
    arm = load_arm()
    for q, v in _random_states(arm, 500, seed=1):
        native_terms = arm.compute(q, v)
        assert arm._native  # the compiled path ran
        _assert_same_bits(native_terms, _through_bindings(arm, q, v))


def test_nominal_pusher_frame_matches_the_bindings():
    arm = load_arm(ArmConfig(pusher=replace(PusherConfig(), mount_yaw=0.03)))
    for q, v in _random_states(arm, 50, seed=2):
        native_terms = arm.compute(q, v)
        native_nominal = arm.nominal_pusher(native_terms)
        bound_terms = _through_bindings(arm, q, v)
        bound_nominal = arm.nominal_pusher(bound_terms)
        assert native_nominal is not None and bound_nominal is not None
        _assert_same_bits(native_terms, bound_terms)
        for x, y in zip(native_nominal, bound_nominal, strict=True):
            assert x.tobytes() == y.tobytes()
        assert arm.nominal_pusher(native_terms) is None  # only the last pass's terms


def test_a_changed_gravity_reaches_the_library():
    arm = load_arm()
    q, v = next(_random_states(arm, 1, seed=3))
    before = arm.compute(q, v)
    arm.set_gravity(3.0)
    after = arm.compute(q, v)
    assert not np.array_equal(before.g, after.g)
    _assert_same_bits(after, _through_bindings(arm, q, v))


def test_copies_make_their_own_library_model():
    arm = load_arm()
    q, v = next(_random_states(arm, 1, seed=4))
    expected = arm.compute(q, v)
    for other in (copy.deepcopy(arm), pickle.loads(pickle.dumps(arm))):
        assert other._native is None  # not shared: each copy frees its own
        _assert_same_bits(other.compute(q, v), expected)
        assert other._native and other._native.handle != arm._native.handle


def test_fresh_arrays_every_pass():
    arm = load_arm()
    q, v = next(_random_states(arm, 1, seed=5))
    first, second = arm.compute(q, v), arm.compute(q, v)
    for x, y in zip(first, second, strict=True):
        assert not np.shares_memory(x, y)


def test_non_contiguous_and_integer_states_read_correctly():
    arm = load_arm()
    q, v = next(_random_states(arm, 1, seed=6))
    strided_q = np.repeat(q, 2)[::2]
    _assert_same_bits(arm.compute(strided_q, v), arm.compute(q, v))
    zeros = np.zeros(arm.nv, dtype=np.int64)
    _assert_same_bits(arm.compute(q, zeros), arm.compute(q, np.zeros(arm.nv)))


def _pushed_world(native_on: bool, mount_yaw: float, arm_name: str = "kinova-gen2-7dof"):
    """A world whose arm pushes the cube with jittered torques for 300 steps: its step
    results and the nominal pusher frame of every step's terms."""
    pusher = replace(PusherConfig(mass=0.03), mount_yaw=mount_yaw)
    world = make_world(arm=arm_name, pusher=pusher)
    arm = world.arm
    assert arm is not None
    if not native_on:
        arm._native = False
    start = arm.pusher_placement(arm.q_ready)
    world.reset(
        object_pose=(start.translation[0] + world.object.face_offset, start.translation[1], 0.0)
    )
    rng = np.random.default_rng(11)
    push = np.linalg.pinv(arm.pusher_jacobian(world.q)[:3]) @ np.array([0.05, 0.0, 0.0])
    out = []
    for _ in range(300):
        tau = world.gravity_torque() + 20.0 * push + rng.normal(0.0, 0.5, arm.nv)
        result = world.step(tau, implicit_kv=20.0)
        nominal = arm.nominal_pusher(world.arm_terms)
        out.append((result, None if nominal is None else tuple(nominal)))
    return out, world


@pytest.mark.parametrize(
    ("arm_name", "mount_yaw"),
    [("kinova-gen2-7dof", 0.0), ("kinova-gen2-7dof", 0.02), ("kinova-j2s6s200", 0.0),
     ("panda", 0.0)],
)  # fmt: skip
def test_a_world_steps_to_the_same_bits_with_and_without_the_library(arm_name, mount_yaw):
    with_library, world = _pushed_world(True, mount_yaw, arm_name)
    without, _ = _pushed_world(False, mount_yaw, arm_name)
    assert world.arm._native  # the step end ran through the library
    touching = sum(bool(np.any(r.contact_forces[:, 0] > 0)) for r, _ in with_library)
    assert touching > 100  # the push is a push
    for (a, nominal_a), (b, nominal_b) in zip(with_library, without, strict=True):
        for name, value in vars(a).items():
            other = getattr(b, name)
            if isinstance(value, np.ndarray):
                assert value.tobytes() == other.tobytes(), name
            else:
                assert value == other, name
        assert (nominal_a is None) == (nominal_b is None) == (mount_yaw == 0.0)
        if nominal_a is not None:
            for x, y in zip(nominal_a, nominal_b, strict=True):
                assert x.tobytes() == y.tobytes()
