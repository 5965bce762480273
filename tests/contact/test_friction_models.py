"""The world's ground friction models (``WorldConfig.friction_model``): the slip-aligned box
stays the default, the fixed models obey Coulomb's law with their polygon's support, and an
arm pushes through any of them."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pushctl import make_world
from pushctl.contact.world_config import FRICTION_MODELS, WorldConfig
from pushctl.errors import ConfigError


def _support(model: str, facets: int, angle: float) -> float:
    """The friction set's support along ``angle`` over the full bound μ_g N."""
    if model == "slip_box":
        return 1.0
    if model == "axis_box":
        return abs(math.cos(angle)) + abs(math.sin(angle))
    half = facets // 2
    return math.pi / facets * sum(abs(math.cos(angle - k * math.pi / half)) for k in range(half))


def test_the_slip_box_is_the_default():
    assert WorldConfig().friction_model == "slip_box" == FRICTION_MODELS[0]
    assert make_world("cube", arm=None).config.friction_model == "slip_box"


@pytest.mark.parametrize(
    ("model", "facets", "angle"),
    [("slip_box", 8, 0.0), ("slip_box", 8, 0.4), ("polygon", 8, 0.0), ("polygon", 8, 0.2),
     ("polygon", 16, 0.3), ("axis_box", 8, 0.0), ("axis_box", 8, math.pi / 4)],
)  # fmt: skip
def test_a_sliding_object_stops_where_its_friction_support_says(model, facets, angle):
    """v0²/(2 a) with a = μ g times the friction set's support along the slide (the points
    all slide one way, so the fixed models' rows all sit at their bounds)."""
    world = make_world("cube", arm=None, mu_ground=0.3, dt=0.001, friction_model=model,
                       facets=facets)  # fmt: skip
    v0 = 0.5
    world.reset((0.0, 0.0, 0.0), (v0 * math.cos(angle), v0 * math.sin(angle), 0.0))
    for _ in range(2000):
        result = world.step()
        if not np.abs(result.object_velocity).max() > 1e-9:
            break
    travelled = math.hypot(*world.object_pose[:2])
    expected = v0**2 / (2 * 0.3 * 9.81 * _support(model, facets, angle))
    assert travelled == pytest.approx(expected, rel=0.02)
    assert abs(world.object_pose[2]) < 1e-9


@pytest.mark.parametrize("model", FRICTION_MODELS)
def test_an_arm_pushes_through_every_friction_model(model):
    world = make_world("cube", friction_model=model, facets=16)
    world.reset()
    for _ in range(20):
        result = world.step(world.gravity_torque())
        assert result.mlcp_converged and np.isfinite(result.object_pose).all()
    problem = world.contact_problem(world.gravity_torque())
    rows = 2 * 4 * (1 if model != "polygon" else 4)  # the cube's 4 corners
    assert len(problem.b) == rows + 2 * len(problem.prongs)


def test_bad_friction_settings_are_refused():
    with pytest.raises(ConfigError, match="friction_model"):
        WorldConfig(friction_model="cone")
    with pytest.raises(ConfigError, match="facets"):
        WorldConfig(friction_model="polygon", facets=10)
    with pytest.raises(ConfigError, match="mujoco"):
        make_world("cube", arm=None, engine="mujoco", friction_model="polygon")
