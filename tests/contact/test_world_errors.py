"""Bad input to make_world / reset / step: a ValueError subclass with a message that says
what is wrong and what is accepted."""

import math

import numpy as np
import pytest

import pushctl
from pushctl.errors import ConfigError, PushctlError, StateError


@pytest.mark.parametrize(
    ("kwargs", "fragment"),
    [
        ({"object": "sphere"}, "cube"),
        ({"arm": "ur5"}, "kinova-gen2-7dof"),
        ({"mu_ground": -0.1}, "mu_ground"),
        ({"mu_contact": math.nan}, "mu_contact"),
        ({"dt": 0.0}, "dt"),
        ({"dt": -0.01}, "dt"),
        ({"object_mass": 0.0}, "mass"),
        ({"object_mass": -1.0}, "mass"),
        ({"armature": [0.01] * 3}, "armature"),
        ({"substeps": 0}, "substeps"),
        ({"slip_iterations": -1}, "slip_iterations"),
        ({"slip_iterations": 2.0}, "slip_iterations"),
        ({"slip_iterations": True}, "slip_iterations"),
    ],
)
def test_make_world_rejects_bad_configuration(kwargs, fragment):
    with pytest.raises(ConfigError, match=fragment) as info:
        pushctl.make_world(**kwargs)
    assert "\n" not in str(info.value)


@pytest.fixture(scope="module")
def world():
    return pushctl.make_world()


@pytest.mark.parametrize(
    "tau",
    [np.zeros(6), np.zeros(8), [0.0] * 6 + [math.nan], [0.0] * 6 + [math.inf], "abc", None],
)
def test_step_rejects_bad_torque(world, tau):
    world.reset()
    with pytest.raises(StateError, match="tau"):
        world.step(tau)


@pytest.mark.parametrize(
    ("kwargs", "fragment"),
    [
        ({"object_pose": (0.4, 0.0)}, "object_pose"),
        ({"object_pose": (0.4, math.nan, 0.0)}, "object_pose"),
        ({"object_velocity": (0.0, 0.0, 0.0, 0.0)}, "object_velocity"),
        ({"arm_q": np.zeros(6)}, "arm_q"),
        ({"arm_v": [math.nan] * 7}, "arm_v"),
    ],
)
def test_reset_rejects_bad_state(world, kwargs, fragment):
    with pytest.raises(StateError, match=fragment):
        world.reset(**kwargs)


def test_bad_implicit_gain_is_rejected(world):
    world.reset()
    with pytest.raises(StateError, match="implicit_kv"):
        world.step(np.zeros(7), implicit_kv=-1.0)


def test_errors_are_value_errors():
    assert issubclass(PushctlError, ValueError)
    assert issubclass(ConfigError, PushctlError) and issubclass(StateError, PushctlError)
