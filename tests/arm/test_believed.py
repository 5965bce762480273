"""The controller's terms of a mounted pusher taken from the world arm's own pass
(:class:`pushctl.arm.BelievedTerms`) are, to the bit, what the controller's own model of the
arm (the nominal pusher) computes."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from pushctl.arm import ArmConfig, BelievedTerms, load_arm
from pushctl.arm.believed import same_gravity_terms
from pushctl.config import PusherConfig
from pushctl.errors import ConfigError

ERRORS = ((0.0005, -0.0003), (-0.0002, 0.0004))
# Mounting yaws [rad] whose plate centre of mass comes out the same to the bit as the
# nominal plate's (the first two) and one ulp-level different (the last two): both paths.
YAWS = (-0.015882615275568016, 0.0045608242075092795, 0.011626107904639613, 0.00930063875082393)


@pytest.fixture(scope="module")
def nominal():
    return load_arm(ArmConfig(pusher=PusherConfig()))


def _states(arm, n, seed=0):
    rng = np.random.default_rng(seed)
    for _ in range(n):
        yield arm.q_ready + rng.normal(0.0, 0.8, arm.nq), rng.normal(0.0, 0.5, arm.nv)


def _assert_controller_terms_equal(got, expected) -> None:
    for name in ("g", "pusher_position", "pusher_rotation", "pusher_jacobian"):
        a, b = getattr(got, name), getattr(expected, name)
        assert a.shape == b.shape and a.tobytes() == b.tobytes(), name


def test_gravity_as_computed_is_compute_s_g_to_the_bit(nominal) -> None:
    mounted = load_arm(ArmConfig(pusher=replace(PusherConfig(), mount_yaw=YAWS[2])))
    for arm in (nominal, mounted):
        for q, v in _states(arm, 50):
            assert arm.gravity_as_computed(q).tobytes() == arm.compute(q, v).g.tobytes()
    # and it is g: RNEA agrees to rounding
    q = nominal.q_ready + 0.3
    np.testing.assert_allclose(nominal.gravity_as_computed(q), nominal.gravity(q), atol=1e-12)


def test_believed_terms_equal_the_nominal_model_s_to_the_bit(nominal) -> None:
    paths = set()
    for yaw in YAWS:
        world = load_arm(
            ArmConfig(pusher=replace(PusherConfig(), mount_yaw=yaw, prong_errors=ERRORS))
        )
        believed = BelievedTerms(world, nominal)
        paths.add(believed.same_gravity)
        for q, v in _states(world, 40, seed=int(1e6 * abs(yaw))):
            terms = world.compute(q, v)
            got, expected = believed(terms, q, v), nominal.compute(q, v)
            _assert_controller_terms_equal(got, expected)
            # the world's own frame is the mounted one, turned by the yaw from the believed
            turn = got.pusher_rotation.T @ terms.pusher_rotation
            assert math.atan2(turn[1, 0], turn[0, 0]) == pytest.approx(yaw, abs=1e-12)
            assert got.M is terms.M and got.prong_positions is terms.prong_positions
    assert paths == {True, False}  # the world's g and the fallback both exercised


def test_prong_errors_alone_leave_the_world_s_pusher_frame_the_believed_one(nominal) -> None:
    world = load_arm(ArmConfig(pusher=replace(PusherConfig(), prong_errors=ERRORS)))
    assert world.nominal_pusher_frame_id is None
    believed = BelievedTerms(world, nominal)
    assert believed.same_gravity
    for q, v in _states(world, 20):
        terms = world.compute(q, v)
        assert world.nominal_pusher(terms) is None and believed(terms, q, v) is terms
        _assert_controller_terms_equal(terms, nominal.compute(q, v))


def test_the_nominal_frame_changes_nothing_the_world_computes(monkeypatch) -> None:
    """One more frame on the mounted arm's model: its own terms are those of a model without."""
    import pushctl.arm.model as model_module

    pusher = replace(PusherConfig(), mount_yaw=YAWS[0], prong_errors=ERRORS)
    world = load_arm(ArmConfig(pusher=pusher))
    monkeypatch.setattr(model_module, "add_frame_on_ee", lambda *args: None)
    bare = load_arm(ArmConfig(pusher=pusher))
    assert bare.model.nframes == world.model.nframes - 1
    assert world.nominal_pusher_frame_id == world.model.nframes - 1
    assert bare.q_ready.tobytes() == world.q_ready.tobytes()
    for q, v in _states(world, 10):
        a, b = world.compute(q, v), bare.compute(q, v)
        assert world.nominal_pusher(a) is not None and bare.nominal_pusher(b) is None
        for x, y in zip(a, b, strict=True):
            assert x.tobytes() == y.tobytes()


def test_terms_of_an_earlier_pass_get_the_controller_model_s_whole_pass(nominal) -> None:
    world = load_arm(ArmConfig(pusher=replace(PusherConfig(), mount_yaw=YAWS[1])))
    believed = BelievedTerms(world, nominal)
    (q, v), (q2, v2) = _states(world, 2, seed=7)
    earlier = world.compute(q, v)
    assert world.nominal_pusher(earlier) is not None
    latest = world.compute(q2, v2)
    assert world.nominal_pusher(earlier) is None  # its pass is no longer the last one
    _assert_controller_terms_equal(believed(earlier, q, v), nominal.compute(q, v))
    # the energy correction's copy (World._advance_arm) keeps the pass's Jacobian
    rescaled = latest._replace(nle=latest.g)
    assert world.nominal_pusher(rescaled) is world.nominal_pusher(latest) is not None


def test_believed_terms_refuse_a_controller_arm_with_another_pusher(nominal) -> None:
    world = load_arm(ArmConfig(pusher=replace(PusherConfig(), mount_yaw=0.01)))
    other = load_arm(ArmConfig(pusher=replace(PusherConfig(), width=0.08)))
    with pytest.raises(ConfigError, match="nominal pusher"):
        BelievedTerms(world, other)
    assert not same_gravity_terms(world, load_arm(ArmConfig(pusher=PusherConfig(mass=0.5))))


def test_the_world_s_g_is_not_the_controller_s_when_the_plate_centres_differ(nominal) -> None:
    """Why the fallback: with a last-bit difference of the plate's centre of mass the
    world's g differs from the controller model's in the last bit at some states (3 of the
    first 500 here), where the believed terms still agree."""
    world = load_arm(ArmConfig(pusher=replace(PusherConfig(), mount_yaw=YAWS[2])))
    believed = BelievedTerms(world, nominal)
    assert not believed.same_gravity
    rng = np.random.default_rng(0)
    differ = 0
    for _ in range(500):
        q, v = nominal.q_ready + rng.normal(0.0, 0.8, nominal.nq), np.zeros(nominal.nv)
        terms, expected = world.compute(q, v), nominal.compute(q, v)
        differ += terms.g.tobytes() != expected.g.tobytes()
        assert believed(terms, q, v).g.tobytes() == expected.g.tobytes()
    assert differ > 0
    np.testing.assert_allclose(terms.g, expected.g, rtol=1e-14)
