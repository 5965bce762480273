"""Plant unknowns that change the forces, not the motion (docs/design.md §6): the centre of
pressure of the support loads (c) and ground friction varying over the table (d), and the
two force errors they separate."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from pushctl.config import GRAVITY
from pushctl.contact.ground_field import FrictionField, support_positions
from pushctl.engines import make_world
from pushctl.episode.draw import draw_planned_scenario
from pushctl.episode.metrics import compute_metrics
from pushctl.episode.runner import Episode
from pushctl.episode.unknowns import NO_UNKNOWNS, PlantUnknowns, with_unknown_loads
from pushctl.errors import ConfigError
from pushctl.objects import resolve_object, support_loads, with_pressure_offset

# ------------------------------------------------------------- (c) centre of pressure


@given(
    obj=st.sampled_from(["cube", "wedge"]),
    fn=st.floats(-0.2, 0.2),
    ft=st.floats(-0.2, 0.2),
)
def test_shifted_loads_keep_the_weight_stay_non_negative_and_centre_where_asked(obj, fn, ft):
    spec = resolve_object(obj)
    shifted = with_unknown_loads(spec, PlantUnknowns(pressure_offset=(fn, ft)))
    loads, points = shifted.support_loads, shifted.support_points
    assert loads.sum() == pytest.approx(spec.mass * GRAVITY, rel=1e-12)
    assert loads.min() >= 0.0
    half = 0.5 * np.ptp(spec.footprint, axis=0)
    np.testing.assert_allclose(
        loads @ points / loads.sum(), [fn * half[0], ft * half[1]], atol=1e-12
    )


def test_a_pressure_offset_loads_the_near_corners_and_none_changes_nothing():
    cube = resolve_object("cube")
    forward = with_pressure_offset(cube, [0.0044, 0.0])  # 10 % of the 44 mm half-extent
    front = cube.support_points[:, 0] > 0.0
    assert np.all(forward.support_loads[front] > forward.support_loads[~front])
    assert with_unknown_loads(cube, NO_UNKNOWNS) is cube
    assert forward != cube and with_pressure_offset(cube, [0.0, 0.0]) == cube
    with pytest.raises(ConfigError, match="outside the support"):
        support_loads(np.asarray(cube.support_points), 1.0, centre=np.array([0.05, 0.0]))


def _scenario(obj="cube", profile="constant", seed=1):
    scenario, _, plan = draw_planned_scenario(seed, "tuning", obj, profile, plant="sim")
    return scenario.with_unknowns(NO_UNKNOWNS), plan


def test_a_pressure_offset_changes_the_forces_the_plant_needs_not_the_motion():
    """With both prongs sticking the object is locked to the pusher: other loads change
    the forces, and the plant forces (the true loads) follow them while the plan does not."""
    scenario, plan = _scenario()
    base = Episode(scenario, plan=plan)
    loaded = Episode(scenario.with_unknowns(PlantUnknowns(pressure_offset=(0.1, 0.1))), plan=plan)
    a, b = base.run(), loaded.run()
    np.testing.assert_allclose(b.object_pose, a.object_pose, atol=5e-5)
    ma, mb = compute_metrics(a), compute_metrics(b)
    assert mb.force_error < 2e-3  # the controller gives what the plant needs
    assert mb.force_error_plan > ma.force_error_plan + 0.01  # the plan did not know
    np.testing.assert_array_equal(b.plan_forces, plan.forces.forces)
    # the torque the plant needed about the centre of mass changed with the loads
    assert np.abs(loaded.plant_forces.total_torque - base.plant_forces.total_torque).max() > 1e-3


# ------------------------------------------------------- (d) friction over the table


def test_the_friction_field_is_seeded_bounded_and_stationary_with_its_length():
    field = FrictionField(0.1, 0.05, seed=11)
    points = np.random.default_rng(0).uniform(-1.0, 1.0, size=(5000, 2))
    values = field(points)
    assert np.all((values > 0.9) & (values < 1.1)) and values.std() > 0.02
    # the compiled per-step path is the documented formula over the mode sum
    np.testing.assert_allclose(values, 1 + 0.1 * np.tanh(field.unit_field(points) / 2), atol=1e-13)
    np.testing.assert_array_equal(values, FrictionField(0.1, 0.05, seed=11)(points))
    assert not np.array_equal(values, FrictionField(0.1, 0.05, seed=12)(points))
    # unit variance, and the squared-exponential correlation exp(−r²/2ℓ²) at r = ℓ and 3ℓ,
    # over many fields (each has 128 modes: the ensemble, not one field, is Gaussian)
    rng = np.random.default_rng(1)
    p = rng.uniform(-0.5, 0.5, size=(200, 2))
    direction = rng.normal(size=(200, 2))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    f0, f1, f3 = [], [], []
    for seed in range(300):
        unit = FrictionField(0.1, 0.05, seed).unit_field
        f0.append(unit(p))
        f1.append(unit(p + 0.05 * direction))
        f3.append(unit(p + 0.15 * direction))
    f0, f1, f3 = (np.concatenate(x) for x in (f0, f1, f3))
    assert f0.var() == pytest.approx(1.0, abs=0.05)
    assert np.mean(f0 * f1) == pytest.approx(math.exp(-0.5), abs=0.05)
    assert np.mean(f0 * f3) == pytest.approx(math.exp(-4.5), abs=0.05)


def test_the_world_s_per_step_bounds_are_the_field_at_its_support_points() -> None:
    """update_support_bounds rewrites the limits in place with μ_g N_j times the field at
    each support point's table position, the same floats as the field's own call, and
    scales only the warm start's ground rows (the last 2 S) by new/old, in a new array."""
    field = FrictionField(0.2, 0.05, seed=3)
    support = np.array([[0.03, 0.03], [-0.03, 0.03], [-0.03, -0.03], [0.03, -0.03]])
    uniform = np.array([0.5, 0.6, 0.7, 0.8])
    pose = np.array([0.41, -0.07, 0.6])
    old = np.array([0.45, 0.7, 0.65, 0.9])
    limits = old.copy()
    guess = np.arange(1.0, 11.0)  # two prong rows, then two per support point
    kept = guess.copy()
    scaled = field.update_support_bounds(pose, support, uniform, limits, guess)
    expected = uniform * field(support_positions(pose, support))
    assert limits.tobytes() == expected.tobytes()
    assert scaled is not None and scaled is not guess
    assert guess.tobytes() == kept.tobytes()
    assert scaled[:2].tobytes() == guess[:2].tobytes()
    ratio = np.repeat(expected / old, 2)
    assert scaled[2:].tobytes() == (guess[2:] * ratio).tobytes()
    assert field.update_support_bounds(pose, support, uniform, limits, None) is None


def test_bad_field_parameters_are_one_line_errors():
    with pytest.raises(ConfigError, match="variation must be in"):
        FrictionField(1.5, 0.05, 0)
    with pytest.raises(ConfigError, match="correlation length must be > 0"):
        FrictionField(0.1, 0.0, 0)


def test_a_sliding_object_decelerates_by_the_field_s_friction_at_its_corners():
    """Analytic check: a free cube sliding along +x without turning feels
    −Σ μ_g f(p_j) N_j over one step, f at each support point's table position; the
    uneven friction also turns it (a torque about the centre of mass)."""
    field = FrictionField(0.2, 0.05, seed=5)
    pose, v0, h = np.array([0.4, 0.1, 0.3]), 0.2, 0.001
    worlds = {
        "uniform": make_world("cube", arm=None, mu_ground=0.3, dt=h),
        "field": make_world("cube", arm=None, mu_ground=0.3, dt=h, friction_field=field),
    }
    spec = worlds["field"].object
    corners = support_positions(pose, np.asarray(spec.support_points))
    limits = 0.3 * spec.support_loads * field(corners)
    for name, world in worlds.items():
        world.reset(object_pose=pose, object_velocity=(v0, 0.0, 0.0))
        result = world.step()
        expected = limits.sum() if name == "field" else 0.3 * spec.mass * GRAVITY
        decel = (v0 - result.object_velocity[0]) / h
        assert decel == pytest.approx(expected / spec.mass, rel=1e-6)
    # the field's friction differs from corner to corner, so it turns the cube
    assert abs(worlds["field"].object_velocity[2]) > 1e-6
    assert abs(worlds["uniform"].object_velocity[2]) < 1e-12


def test_friction_over_the_table_changes_the_plant_forces_not_the_motion():
    scenario, plan = _scenario(seed=2)
    rough = PlantUnknowns(ground_variation=0.2, ground_length=0.05, ground_seed=3)
    base, varied = Episode(scenario, plan=plan), Episode(scenario.with_unknowns(rough), plan=plan)
    assert base.world.friction_field is None and varied.world.friction_field is not None
    a, b = base.run(), varied.run()
    np.testing.assert_allclose(b.object_pose, a.object_pose, atol=5e-5)
    ma, mb = compute_metrics(a), compute_metrics(b)
    assert mb.force_error < 2e-3
    assert mb.force_error_plan > ma.force_error_plan + 0.002
    assert np.abs(varied.plant_forces.forces - base.plant_forces.forces).max() > 0.01
    assert varied.world.stats.warm_starts > 0.9 * varied.world.stats.solves
    # the world's bounds are the field at the support points' table positions
    world = varied.world
    corners = support_positions(world.object_pose, np.asarray(world.object.support_points))
    world.contact_problem(np.zeros(world.v.size))  # the bounds at the current pose
    expected = (
        scenario.true_parameters.mu_ground
        * world.object.support_loads
        * world.friction_field(corners)
    )
    np.testing.assert_allclose(world.solver.model.friction_limits, expected, rtol=1e-12)


def test_bounds_are_not_recomputed_while_the_object_rests_and_the_trace_is_the_same(
    monkeypatch,
):
    """The world skips the field's query where the object's pose is the one the bounds were
    computed at (most approach steps): the same trace to the byte as a world that queries
    every step, with fewer queries."""
    scenario, plan = _scenario(seed=2)
    rough = PlantUnknowns(ground_variation=0.2, ground_length=0.05, ground_seed=3)
    queries = []
    update = FrictionField.update_support_bounds

    def counted(self, *args):
        queries.append(1)
        return update(self, *args)

    monkeypatch.setattr(FrictionField, "update_support_bounds", counted)
    traces, counts = [], []
    for skip in (True, False):
        episode = Episode(scenario.with_unknowns(rough), plan=plan)
        world = episode.world
        if not skip:  # forget the pose before every step: each one queries the field
            step = world.step

            def step_forgetting(*args, step=step, world=world, **kwargs):
                world.solver._bounds_at = None
                return step(*args, **kwargs)

            world.step = step_forgetting
        queries.clear()
        trace = episode.run()
        counts.append((len(queries), world.stats.steps))
        traces.append(b"".join(np.ascontiguousarray(a).tobytes() for a in vars(trace).values()
                               if isinstance(a, np.ndarray)))  # fmt: skip
    assert len(traces[0]) > 10_000 and traces[0] == traces[1]
    (skipping, steps), (every, _) = counts
    assert every == steps  # one query per step without the skip
    assert skipping < steps - 100  # the approach's resting steps skipped it
