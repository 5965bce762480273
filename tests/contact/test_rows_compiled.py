"""The compiled prong geometry of the world step agrees bit for bit with ConvexPolygon.query."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pushctl.contact.rows import edge_array, prong_contacts, prong_geometry
from pushctl.objects import make_object


def _reference(polygon, pose, prongs, margin):
    """prong_contacts as it was written in Python on ConvexPolygon.query (uncompiled)."""
    x0, y0, theta = pose.tolist()
    c, s = math.cos(theta), math.sin(theta)
    index, geometry, gaps = [], [], []
    for i, (px, py, _) in enumerate(prongs.tolist()):
        px, py = px - x0, py - y0
        gap, nx, ny, cx, cy = polygon.query(c * px + s * py, -s * px + c * py)
        gaps.append(gap)
        if gap < margin:
            index.append(i)
            geometry.append((gap, -(c * nx - s * ny), -(s * nx + c * ny), c * cx - s * cy,
                             s * cx + c * cy))  # fmt: skip
    return tuple(index), np.array(geometry, dtype=float).reshape(-1, 5), np.array(gaps)


@pytest.mark.parametrize("name", ["cube", "wedge"])
def test_compiled_geometry_matches_polygon_query_bit_for_bit(name):
    polygon = make_object(name).polygon
    edges = edge_array(polygon)
    rng = np.random.default_rng(15)
    size = float(np.abs(polygon.vertices).max())
    for _ in range(400):
        pose = np.array([*rng.uniform(-0.05, 0.05, 2), rng.uniform(-4.0, 4.0)])
        prongs = np.column_stack([pose[:2] + rng.uniform(-2 * size, 2 * size, (2, 2)),
                                  np.zeros(2)])  # fmt: skip
        if rng.random() < 0.2:  # exactly on a vertex: the zero-distance branch
            c, s = math.cos(pose[2]), math.sin(pose[2])
            vx, vy = polygon.vertices[rng.integers(len(polygon.vertices))]
            prongs[0, :2] = pose[:2] + (c * vx - s * vy, s * vx + c * vy)
        expected = _reference(polygon, pose, prongs, 0.01)
        got = prong_contacts(polygon, pose, prongs, 0.01, edges)
        assert got[0] == expected[0]
        assert got[1].tobytes() == expected[1].tobytes()
        assert got[2].tobytes() == expected[2].tobytes()
    # both branches seen: a prong inside and one outside of the footprint
    _, gaps, mask = prong_geometry(
        edges, np.zeros(3), np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]), 0.01
    )
    assert mask == 1
    assert gaps[0] < 0.0 < gaps[1]


def test_arm_terms_of_a_deep_copy_follow_its_own_state():
    """ArmModel keeps views of its Pinocchio Data: a deep copy must compute from its own."""
    import copy

    from pushctl.arm import load_arm

    arm = load_arm()
    twin = copy.deepcopy(arm)
    q = arm.q_ready + 0.1
    v = np.linspace(-0.3, 0.3, arm.nv)
    expected = arm.compute(q, v)
    arm.compute(arm.q_ready, np.zeros(arm.nv))  # the original's Data moves elsewhere
    got = twin.compute(q, v)
    for a, b in zip(expected, got, strict=True):
        assert np.array_equal(a, b)
    assert not np.shares_memory(twin._data_M, arm._data_M)


def test_step_state_and_contact_model_name_the_kernels_parameters():
    """The world calls the kernels as ``kernel(*state, *model, ...)``: STEP_STATE and the
    ContactModel's fields must be their parameters in order, or arrays would land in the
    wrong parameter."""
    import inspect

    from pushctl.contact.compiled.assembly import assemble
    from pushctl.contact.compiled.step import fixed_problem, fixed_step, resume_step, slip_step
    from pushctl.contact.step_solver import STEP_STATE, ContactModel

    names = list(STEP_STATE) + list(ContactModel._fields)
    assert len(names) == 18
    for kernel in (assemble, slip_step, resume_step, fixed_step, fixed_problem):
        parameters = list(inspect.signature(kernel.py_func).parameters)
        assert parameters[:18] == names, kernel.py_func.__name__
    assert list(inspect.signature(assemble.py_func).parameters) == names


def test_the_contact_model_follows_the_worlds_arrays():
    """Built once per world, its arrays updated in place: a contact problem leaves the
    boxes as they were."""
    from pushctl import make_world

    world = make_world("cube")
    model = world.solver.model
    directions = model.slip_directions
    assert model.h == world.config.dt / world.config.substeps
    before = directions.copy()
    world.contact_problem(np.zeros(world.v.size))  # restores the boxes in place
    assert world.solver.model.slip_directions is directions
    assert np.array_equal(directions, before)
