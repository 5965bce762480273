"""Object-only worlds against analytic friction results (docs/design.md §3, ground friction)."""

import math
from pathlib import Path

import numpy as np
import pytest

import pushctl
from pushctl.config import GRAVITY


def slide_until_rest(world, max_steps=20_000):
    """Step until the object stops (|v| < 1e-9 in each component); returns the final pose."""
    for _ in range(max_steps):
        result = world.step()
        if np.abs(result.object_velocity).max() < 1e-9:
            return result.object_pose
    raise AssertionError("object never came to rest")


@pytest.mark.parametrize(
    ("object_name", "mu", "speed", "heading_deg", "theta0"),
    [
        ("cube", 0.3, 0.5, 0.0, 0.0),  # along the face normal
        ("cube", 0.3, 0.5, 45.0, 0.0),  # along the diagonal of a ground box at rest
        ("cube", 0.22, 0.35, 120.0, 0.4),  # rotated body, oblique slide
        ("wedge", 0.38, 0.4, -30.0, -0.2),  # unequal support loads
    ],
)
def test_free_slide_stops_at_v0_squared_over_2_mu_g(object_name, mu, speed, heading_deg, theta0):
    dt = 1e-3
    world = pushctl.make_world(object=object_name, arm=None, mu_ground=mu, dt=dt)
    heading = math.radians(heading_deg)
    velocity = (speed * math.cos(heading), speed * math.sin(heading), 0.0)
    world.reset(object_pose=(0.4, 0.1, theta0), object_velocity=velocity)
    final = slide_until_rest(world)
    travelled = final[:2] - np.array([0.4, 0.1])
    expected = speed**2 / (2 * mu * GRAVITY)
    # Semi-implicit Euler stops short by ~v0·h/2; isotropic friction keeps the heading.
    assert np.linalg.norm(travelled) == pytest.approx(expected, abs=speed * dt)
    direction = travelled / np.linalg.norm(travelled)
    assert direction @ np.array(velocity[:2]) / speed > 1 - 1e-6
    assert final[2] == pytest.approx(theta0, abs=1e-6)


def test_stopping_distance_converges_with_the_step():
    errors = []
    for dt in (1e-2, 1e-3):
        world = pushctl.make_world(object="cube", arm=None, mu_ground=0.3, dt=dt)
        world.reset(object_pose=(0, 0, 0), object_velocity=(0.6, 0, 0))
        final = slide_until_rest(world)
        errors.append(abs(final[0] - 0.36 / (2 * 0.3 * GRAVITY)))
    assert errors[1] < errors[0] / 5


@pytest.mark.parametrize(("mu", "omega0"), [(0.3, 3.0), (0.45, -5.0)])
def test_spinning_cube_stops_at_its_torsional_friction_angle(mu, omega0):
    world = pushctl.make_world(object="cube", arm=None, mu_ground=mu, dt=1e-3)
    spec = world.object
    radii = np.linalg.norm(spec.support_points, axis=1)
    torque = mu * float(spec.support_loads @ radii)  # each corner slides on its circle
    expected = omega0**2 / (2 * torque / spec.inertia_z)
    world.reset(object_pose=(0.5, 0.0, 0.0), object_velocity=(0.0, 0.0, omega0))
    final = slide_until_rest(world)
    assert abs(final[2]) == pytest.approx(expected, abs=abs(omega0) * 1e-3)
    assert math.copysign(1, final[2]) == math.copysign(1, omega0)
    assert np.allclose(final[:2], (0.5, 0.0), atol=1e-9)  # symmetric: no net force


@pytest.mark.parametrize("object_name", ["cube", "wedge"])
def test_object_at_rest_stays_at_rest(object_name):
    world = pushctl.make_world(object=object_name, arm=None)
    world.reset(object_pose=(0.45, -0.02, 0.3))
    for _ in range(500):
        result = world.step()
    assert np.allclose(result.object_pose, [0.45, -0.02, 0.3], rtol=0, atol=1e-12)
    assert np.abs(result.object_velocity).max() < 1e-12


def test_slow_object_stops_within_one_step():
    """Friction that can stop the object in a step does so exactly (sticking, no reversal)."""
    world = pushctl.make_world(object="cube", arm=None, mu_ground=0.3, dt=0.01)
    world.reset(object_pose=(0, 0, 0), object_velocity=(0.01, 0.005, 0.05))
    result = world.step()
    assert not np.any(np.abs(result.object_velocity) > 1e-12)
    assert result.mlcp_residual < 1e-9


def test_friction_free_object_keeps_its_momentum():
    world = pushctl.make_world(object="wedge", arm=None, mu_ground=0.0, dt=0.01)
    world.reset(object_pose=(0, 0, 0), object_velocity=(0.1, -0.05, 0.2))
    for _ in range(100):
        result = world.step()
    assert np.allclose(result.object_velocity, (0.1, -0.05, 0.2), atol=1e-12)
    assert np.allclose(result.object_pose, (0.1, -0.05, 0.2), atol=1e-12)


def test_substeps_refine_the_step():
    def distance(substeps):
        world = pushctl.make_world(object="cube", arm=None, dt=0.01, substeps=substeps)
        world.reset(object_pose=(0, 0, 0), object_velocity=(0.6, 0, 0))
        return slide_until_rest(world)[0]

    exact = 0.36 / (2 * 0.3 * GRAVITY)
    assert abs(distance(8) - exact) < abs(distance(1) - exact) / 4


def test_a_toml_prism_slides_like_the_presets():
    hexagon = Path(__file__).resolve().parents[2] / "experiments/objects/hexagon.toml"
    world = pushctl.make_world(object=str(hexagon), arm=None, mu_ground=0.4, dt=1e-3)
    spec = world.object
    assert spec.mass == pytest.approx(0.25)
    assert spec.support_loads.sum() == pytest.approx(0.25 * GRAVITY)
    assert spec.face_offset == pytest.approx(0.0433, abs=1e-4)  # flat side towards the arm
    world.reset(object_pose=(0, 0, 0), object_velocity=(0.4, 0.1, 0.0))
    final = slide_until_rest(world)
    assert np.linalg.norm(final[:2]) == pytest.approx(0.17 / (2 * 0.4 * GRAVITY), abs=4e-4)


@pytest.mark.parametrize(
    "velocity", [(0.05, 0.0, 2.0), (0.08, 0.02, 1.5), (-0.04, 0.05, -2.5), (0.03, 0.03, 2.0)]
)
def test_ground_friction_opposes_the_slip_after_the_step(velocity):
    """Coulomb friction acts against each support point's velocity *after* the step: with
    h = 10 ms a spinning, sliding object's support velocities turn by tens of degrees within
    one step, and the simulated wrench matches the planner's sliding friction evaluated at
    the new velocity (its boxes sit within 5° of it, so within μ_g m g·2 sin 2.5° ≈ 9 %),
    not at the old one."""
    from pushctl.planning.ground import sliding_friction

    h, mu = 0.01, 0.3
    world = pushctl.make_world(object="cube", arm=None, mu_ground=mu, dt=h)
    obj = world.object
    pose = np.array([0.4, 0.0, 0.3])
    world.reset(object_pose=pose, object_velocity=velocity)
    after = world.step().object_velocity
    simulated = (after - velocity) / h * np.array([obj.mass, obj.mass, obj.inertia_z])
    scale = mu * obj.mass * GRAVITY
    at_new = sliding_friction(obj, mu, pose[None], after[None])[0]
    at_old = sliding_friction(obj, mu, pose[None], np.array([velocity], float))[0]
    assert world.stats.slip_iterations > 0 and world.stats.slip_unsettled == 0
    assert np.linalg.norm(simulated[:2] - at_new[:2]) < 0.09 * scale
    assert np.linalg.norm(simulated[:2] - at_old[:2]) > np.linalg.norm(simulated[:2] - at_new[:2])


@pytest.mark.parametrize("iterations", [0, 1, 2])
def test_slip_iterations_bound_the_re_solves(iterations):
    """``slip_iterations`` caps the re-solves of each step. This first step settles after two
    (by default at most six): capped below that it keeps the friction boxes of the velocity
    before it (the one-step-lag model), whose friction is further from the sliding friction
    at the new velocity; capped at two it is the default's step to the bit."""
    from pushctl.planning.ground import sliding_friction

    h, mu, velocity = 0.01, 0.3, (0.08, 0.02, 1.5)
    pose = np.array([0.4, 0.0, 0.3])

    def first_step(slip_iterations):
        world = pushctl.make_world(
            object="cube", arm=None, mu_ground=mu, dt=h, slip_iterations=slip_iterations
        )
        world.reset(object_pose=pose, object_velocity=velocity)
        return world, world.step().object_velocity

    default_world, default_after = first_step(6)
    assert default_world.stats.slip_iterations == 2 and default_world.stats.slip_unsettled == 0
    world, after = first_step(iterations)
    assert world.stats.slip_iterations == iterations
    for _ in range(30):  # sliding and spinning down: every step within the cap
        before = world.stats.slip_iterations
        world.step()
        assert world.stats.slip_iterations - before <= iterations
    if iterations == 2:
        assert after.tobytes() == default_after.tobytes()
        return
    obj = world.object
    scale = np.array([obj.mass, obj.mass, obj.inertia_z]) / h

    def miss(velocity_after):  # distance to the sliding friction at the new velocity [N]
        simulated = (velocity_after - velocity) * scale
        at_new = sliding_friction(obj, mu, pose[None], velocity_after[None])[0]
        return np.linalg.norm(simulated[:2] - at_new[:2])

    assert miss(after) > 2 * miss(default_after)
