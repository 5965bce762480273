"""make_plan end to end (docs/design.md §4, §8): with the Kinova arm's reach, the pusher path on
the pushed face, out-of-reach and malformed goals, and the plan table."""

import math
import re

import numpy as np
import pytest

from pushctl.arm import ArmConfig, load_arm
from pushctl.config import PusherConfig
from pushctl.errors import ConfigError, PlanError
from pushctl.objects import make_object, to_local
from pushctl.planning import default_start, make_plan

COLUMNS = [
    "t", "x", "y", "theta", "vx", "vy", "omega", "ax", "ay", "alpha", "icr_x", "icr_y",
    "force_n_des_1", "force_t_des_1", "force_n_des_2", "force_t_des_2",
    "tau_z_des_1", "tau_z_des_2", "tau_z_des", "ne_residual",
]  # fmt: skip


@pytest.fixture(scope="module")
def arms():
    """The Kinova Gen2 7-DOF with each object's Table II pusher, loaded once."""
    return {
        name: load_arm(ArmConfig(pusher=PusherConfig(mass=make_object(name).pusher_mass)))
        for name in ("cube", "wedge")
    }


def goal_from(obj, arm, dx, dy, dtheta_deg):
    start = default_start(obj, arm.ready_pusher_position)
    return (start.x + dx, start.y + dy, start.theta + math.radians(dtheta_deg))


@pytest.fixture(scope="module")
def plans(arms):
    """Feasible plans at the far corners of docs/design.md §7's ranges (the hardest to reach)."""
    out = {}
    for name in ("cube", "wedge"):
        obj, arm = make_object(name), arms[name]
        for goal in ((0.25, 0.05, 45.0), (0.25, -0.05, -45.0), (0.10, 0.0, 10.0)):
            out[name, goal] = make_plan(obj, goal_from(obj, arm, *goal), arm=arm)
    return out


def test_default_start_is_ahead_of_the_ready_pusher(arms):
    for name, arm in arms.items():
        obj = make_object(name)
        assert arm.name == "kinova-gen2-7dof"
        np.testing.assert_allclose(arm.ready_pusher_position, [0.30, 0.0, 0.06], atol=1e-9)
        start = default_start(obj, arm.ready_pusher_position)
        # the pushed face 76 mm ahead of the ready prongs, CoM inside docs/design.md §3's
        # 0.40–0.45 m
        assert start.x - obj.face_offset == pytest.approx(0.376, abs=1e-9)
        assert 0.40 <= start.x <= 0.45 and start.y == 0.0 and start.theta == 0.0
        plan = make_plan(obj, (start.x + 0.2, 0.0, 0.0), arm=arm, dt=0.1)
        np.testing.assert_allclose(plan.trajectory.pose[0], start.as_array(), atol=1e-15)


def test_evaluation_corner_plans_are_feasible_and_well_conditioned(plans):
    for key, plan in plans.items():
        assert plan.feasible and plan.problems == (), key
        plan.raise_if_infeasible()  # does not raise
        assert plan.arm_name == "kinova-gen2-7dof"
        reach, steps = plan.reach, plan.reach_steps
        n = plan.trajectory.n_steps
        assert steps[0] == 0 and steps[-1] == n and np.all(np.diff(steps) > 0)
        assert len(steps) == 51
        assert reach.first_unreached is None and reach.reached.all()
        assert np.all(np.isfinite(reach.condition)) and reach.condition.max() < 30, key
        assert reach.position_error.max() < 1e-5 and reach.rotation_error.max() < 1e-4
        assert reach.q.shape == (len(steps), 7)


def test_pusher_positions_put_the_prongs_on_the_pushed_face(plans):
    for key, plan in plans.items():
        obj, tr, fp = plan.obj, plan.trajectory, plan.forces
        prongs = PusherConfig().prong_offsets()
        np.testing.assert_allclose(plan.pusher_yaws, tr.pose[:, 2], atol=1e-15)
        np.testing.assert_allclose(plan.pusher_positions[:, 2], obj.com_height, atol=1e-15)
        for k in range(0, tr.n_steps + 1, 97):
            pose = tr.pose[k]
            e_t = np.array([-math.sin(pose[2]), math.cos(pose[2])])
            for o in prongs:
                point = plan.pusher_positions[k, :2] + o * e_t
                local = to_local(pose, point)
                distance, nx, ny, _, _ = obj.polygon.query(*local)
                assert abs(distance) < 1e-12, key
                assert (nx, ny) == pytest.approx((-1.0, 0.0), abs=1e-12)  # the pushed face
                # at the force plan's prong point, inside the face's ends
                assert local[1] == pytest.approx(fp.offset + o, abs=1e-12)
                assert obj.face_extent[0] < local[1] < obj.face_extent[1]


def test_far_goal_is_out_of_reach(arms):
    obj, arm = make_object("cube"), arms["cube"]
    plan = make_plan(obj, (0.95, 0.0, 0.0), arm=arm, dt=0.1)
    assert plan.forces.feasible  # a straight push: the forces are fine, the arm is not
    assert not plan.feasible and len(plan.problems) == 1
    problem = plan.problems[0]
    assert "out of reach" in problem and "kinova-gen2-7dof" in problem
    with pytest.raises(PlanError) as info:
        plan.raise_if_infeasible()
    assert str(info.value) == problem
    # the named step and pusher position are those of the first unreached pose
    step = int(re.search(r"at step (\d+)", problem).group(1))
    assert step == plan.reach_steps[plan.reach.first_unreached]
    xyz = [
        float(v)
        for v in re.search(r"pusher at \(([-\d.]+), ([-\d.]+), ([-\d.]+)\)", problem).groups()
    ]
    np.testing.assert_allclose(xyz, plan.pusher_positions[step], atol=5e-4)
    # docs/design.md §3: the tool-down posture reaches pushing height only to x ≈ 0.70 m
    assert 0.65 < xyz[0] < 0.80
    assert plan.reach.reached[: plan.reach.first_unreached].all()


@pytest.mark.parametrize(
    "goal",
    [
        (-0.10, 0.0, 0.0),  # straight back: a pull
        (0.0, 0.10, 0.0),  # sideways, 90° off the face normal
        (-0.05, -0.05, 10.0),
    ],
)
def test_goal_behind_the_face_raises(goal):
    obj = make_object("cube")
    start = default_start(obj, np.array([0.30, 0.0, 0.06]))
    with pytest.raises(ConfigError, match="behind"):
        make_plan(obj, (start.x + goal[0], start.y + goal[1], math.radians(goal[2])))


def test_goal_equal_to_start_raises():
    obj = make_object("wedge")
    start = default_start(obj, np.array([0.30, 0.0, 0.06]))
    with pytest.raises(ConfigError):
        make_plan(obj, start.as_array())
    with pytest.raises(ConfigError):
        make_plan(obj, (0.5, 0.1, 0.2), start=(0.5, 0.1, 0.2))
    with pytest.raises(ConfigError):
        make_plan(obj, None)


def test_to_frame_columns_rows_and_values(plans):
    plan = plans["cube", (0.25, 0.05, 45.0)]
    frame = plan.to_frame()
    assert list(frame.columns) == COLUMNS
    tr, fp = plan.trajectory, plan.forces
    assert len(frame) == tr.n_steps + 1 == 2001
    assert not frame.isna().any().any()
    np.testing.assert_array_equal(frame[["x", "y", "theta"]].to_numpy(), tr.pose)
    np.testing.assert_array_equal(frame[["vx", "vy", "omega"]].to_numpy(), tr.velocity)
    np.testing.assert_array_equal(frame[["ax", "ay", "alpha"]].to_numpy(), tr.acceleration)
    np.testing.assert_array_equal(frame[["icr_x", "icr_y"]].to_numpy()[-1], tr.icr)
    np.testing.assert_array_equal(frame["force_n_des_2"], fp.forces[:, 1, 0])
    np.testing.assert_array_equal(frame["tau_z_des"], fp.total_torque)
    np.testing.assert_allclose(
        frame["tau_z_des"], frame["tau_z_des_1"] + frame["tau_z_des_2"], atol=1e-15
    )
    assert frame["ne_residual"].max() < 1e-5
    assert frame["t"].iloc[-1] == pytest.approx(20.0)


def test_straight_plan_frame_has_nan_only_in_the_icr():
    obj = make_object("cube")
    plan = make_plan(obj, (0.6, 0.01, 0.0), dt=0.1)
    assert plan.feasible and plan.arm_name is None and plan.reach is None
    frame = plan.to_frame()
    assert list(frame.columns) == COLUMNS and len(frame) == 201
    nan_columns = frame.columns[frame.isna().any()].tolist()
    assert nan_columns == ["icr_x", "icr_y"]
    assert frame[["icr_x", "icr_y"]].isna().all().all()


def test_identical_calls_give_identical_tables(arms):
    obj, arm = make_object("wedge"), arms["wedge"]
    goal = goal_from(obj, arm, 0.2, -0.03, -25.0)
    for kwargs in ({"arm": arm, "profile": "chirp"}, {"profile": "trapezoid"}):
        first = make_plan(obj, goal, **kwargs).to_frame().to_csv(index=False)
        second = make_plan(obj, goal, **kwargs).to_frame().to_csv(index=False)
        assert first == second
        assert len(first.splitlines()) == 2002  # header + 2001 samples


@pytest.mark.filterwarnings("ignore::RuntimeWarning")
@pytest.mark.parametrize("gravity", [math.nan, math.inf, -9.81])
def test_bad_gravity_raises_config_error(gravity, monkeypatch):
    import pushctl.planning.forces as forces

    solve = forces._StepQP.solve

    def guarded(self, wrenches):
        # without this guard a non-finite wrench keeps ProxQP busy for minutes
        assert np.all(np.isfinite(wrenches)), "a non-finite wrench reached the force QP"
        return solve(self, wrenches)

    monkeypatch.setattr(forces._StepQP, "solve", guarded)
    obj = make_object("cube")
    with pytest.raises(ConfigError):
        make_plan(obj, (0.62, 0.02, 0.3), dt=0.5, gravity=gravity)
