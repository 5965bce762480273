"""Tests of pushctl.objects: mass properties, support loads, presets, TOML and geometry.

References are independent of the code under test: closed forms, scipy's adaptive
quadrature over vertical slices of the polygon, and a dense sampling of the boundary.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import integrate
from scipy.spatial import ConvexHull

from pushctl.config import GRAVITY
from pushctl.errors import ConfigError
from pushctl.objects import (
    OBJECT_NAMES,
    ObjectSpec,
    load_object,
    make_object,
    object_from_footprint,
    polygon_world,
    resolve_object,
    signed_distance,
    signed_distance_batch,
    to_local,
    to_world,
    vectors_to_local,
    vectors_to_world,
    write_object,
)

SQUARE = [[0.0, 0.0], [0.1, 0.0], [0.1, 0.1], [0.0, 0.1]]


# ----------------------------------------------------------------------------- helpers


def random_convex_polygon(rng: np.random.Generator, n_points: int = 9) -> np.ndarray:
    """Counter-clockwise convex polygon (V, 2) [m], a few centimetres across."""
    while True:
        points = rng.uniform(-0.06, 0.06, size=(n_points, 2)) + rng.uniform(-0.2, 0.2, 2)
        hull = ConvexHull(points)
        vertices = points[hull.vertices]  # scipy lists 2-D hull vertices counter-clockwise
        edges = np.roll(vertices, -1, axis=0) - vertices
        if hull.volume > 1e-3 and np.hypot(*edges.T).min() > 1e-3:
            return vertices


def slice_integral(vertices: np.ndarray, f) -> float:
    """∫∫ f(x, y) over a convex polygon by scipy quadrature over vertical slices.

    Between consecutive vertex abscissae the slice bounds are linear in x, so each piece is
    smooth and adaptive quadrature converges to rounding.
    """
    edges = list(zip(vertices, np.roll(vertices, -1, axis=0), strict=True))

    def bounds(x: float) -> tuple[float, float]:
        ys = [
            a[1] + (x - a[0]) * (b[1] - a[1]) / (b[0] - a[0])
            for a, b in edges
            if a[0] != b[0] and min(a[0], b[0]) <= x <= max(a[0], b[0])
        ]
        return min(ys), max(ys)

    xs = np.unique(vertices[:, 0])
    total = 0.0
    for x0, x1 in zip(xs[:-1], xs[1:], strict=True):
        value, _ = integrate.dblquad(
            lambda y, x: f(x, y),
            x0,
            x1,
            lambda x: bounds(x)[0],
            lambda x: bounds(x)[1],
            epsabs=1e-16,
            epsrel=1e-11,
        )
        total += value
    return total


def reference_mass_properties(vertices, height, slope, mass):
    """(volume, com_xy, com_height, inertia_z) by quadrature, in the given coordinates."""

    def h(x, y):
        return height + slope[0] * x + slope[1] * y

    volume = slice_integral(vertices, h)
    com = np.array(
        [
            slice_integral(vertices, lambda x, y: x * h(x, y)) / volume,
            slice_integral(vertices, lambda x, y: y * h(x, y)) / volume,
        ]
    )
    com_height = slice_integral(vertices, lambda x, y: 0.5 * h(x, y) ** 2) / volume
    second = slice_integral(
        vertices, lambda x, y: ((x - com[0]) ** 2 + (y - com[1]) ** 2) * h(x, y)
    )
    return volume, com, com_height, mass / volume * second


def brute_force_distance(vertices: np.ndarray, points: np.ndarray, per_edge: int = 4001):
    """(signed distance (N,), closest (N, 2)) from a dense sampling of the boundary.

    The sign comes from a half-plane test on the counter-clockwise vertices.
    """
    t = np.linspace(0.0, 1.0, per_edge)[:, None]
    boundary = np.concatenate(
        [a + t * (b - a) for a, b in zip(vertices, np.roll(vertices, -1, axis=0), strict=True)]
    )
    gaps = points[:, None, :] - boundary[None, :, :]
    dist2 = np.einsum("nsk,nsk->ns", gaps, gaps)
    nearest = np.argmin(dist2, axis=1)
    edges = np.roll(vertices, -1, axis=0) - vertices
    rel = points[:, None, :] - vertices[None, :, :]
    cross = edges[None, :, 0] * rel[:, :, 1] - edges[None, :, 1] * rel[:, :, 0]
    inside = np.all(cross >= 0.0, axis=1)
    distance = np.sqrt(dist2[np.arange(len(points)), nearest])
    return np.where(inside, -distance, distance), boundary[nearest]


# --------------------------------------------------------------------------- presets


def test_cube_mass_properties_and_loads():
    cube = make_object("cube")
    a = 0.088
    assert cube.mass == 0.300 and cube.pusher_mass == 0.030
    assert cube.inertia_z == pytest.approx(cube.mass * (a**2 + a**2) / 12.0, rel=1e-12)
    assert cube.com_height == pytest.approx(a / 2.0, rel=1e-12)
    assert cube.volume == pytest.approx(a**3, rel=1e-12)
    np.testing.assert_allclose(cube.support_loads, cube.mass * GRAVITY / 4.0, rtol=1e-10)
    assert cube.face_offset == pytest.approx(a / 2.0, rel=1e-12)
    np.testing.assert_allclose(cube.face_extent, [-a / 2.0, a / 2.0], atol=1e-15)
    assert cube.face_height == pytest.approx(a)
    np.testing.assert_allclose(cube.mass_matrix, np.diag([0.3, 0.3, cube.inertia_z]))


def test_wedge_centre_of_mass_and_height():
    wedge = make_object("wedge")
    assert wedge.mass == 0.350 and wedge.pusher_mass == 0.040
    # The back (pushed) face is the line x = -face_offset: the CoM is 140/3 mm in front.
    assert wedge.face_offset == pytest.approx(0.140 / 3.0, rel=1e-12)
    assert wedge.com_height == pytest.approx(0.080 / 3.0, rel=1e-12)
    assert wedge.face_height == pytest.approx(0.080, rel=1e-12)
    assert wedge.face_extent[1] - wedge.face_extent[0] == pytest.approx(0.085)
    np.testing.assert_allclose(wedge.footprint[:, 0].max(), 2.0 * 0.140 / 3.0, rtol=1e-12)
    front = wedge.footprint[wedge.footprint[:, 0] > 0.0]
    np.testing.assert_allclose(wedge.height_at(front), 0.0, atol=1e-15)


def test_wedge_inertia_closed_form_and_quadrature():
    # Ramp on x in [0, L], y in [0, W], height H (1 - x/L), uniform density rho = m / V with
    # V = H W L / 2. About the CoM (x̄ = L/3, ȳ = W/2):
    #   y part: rho ∫∫ (y - W/2)² h dA = rho (W³/12)(H L/2) = m W² / 12.
    #   x part: rho W H ∫ (x - L/3)² (1 - x/L) dx = rho W H L³ ∫₀¹ (u - 1/3)² (1 - u) du,
    #           and (u - 1/3)² (1 - u) = -u³ + 5u²/3 - 7u/9 + 1/9 integrates to
    #           -1/4 + 5/9 - 7/18 + 1/9 = 1/36, so the x part is rho W H L³ / 36 = m L² / 18.
    #   I_z = m (L²/18 + W²/12).
    wedge = make_object("wedge")
    length, width, height = 0.140, 0.085, 0.080
    closed_form = wedge.mass * (length**2 / 18.0 + width**2 / 12.0)
    assert wedge.inertia_z == pytest.approx(closed_form, rel=1e-12)
    ramp = np.array([[0.0, 0.0], [length, 0.0], [length, width], [0.0, width]])
    _, com, com_height, inertia = reference_mass_properties(
        ramp, height, (-height / length, 0.0), wedge.mass
    )
    assert inertia == pytest.approx(wedge.inertia_z, rel=1e-9)
    assert com_height == pytest.approx(wedge.com_height, rel=1e-9)
    np.testing.assert_allclose(com, [length / 3.0, width / 2.0], rtol=1e-9)


def test_wedge_back_corners_carry_two_thirds():
    wedge = make_object("wedge")
    back = np.isclose(wedge.support_points[:, 0], -wedge.face_offset)
    assert back.sum() == 2
    weight = wedge.mass * GRAVITY
    assert wedge.support_loads[back].sum() == pytest.approx(2.0 * weight / 3.0, rel=1e-10)
    np.testing.assert_allclose(wedge.support_loads[back], weight / 3.0, rtol=1e-10)
    np.testing.assert_allclose(wedge.support_loads[~back], weight / 6.0, rtol=1e-10)


def test_presets_are_in_the_local_frame():
    for name in OBJECT_NAMES:
        spec = make_object(name)
        first, second = spec.footprint[0], spec.footprint[1]
        # Edge 0 is the pushed face, vertical at the minimum x, traversed towards -y (ccw).
        assert first[0] == pytest.approx(second[0], abs=1e-15)
        assert first[0] == pytest.approx(spec.footprint[:, 0].min(), abs=1e-15)
        assert first[1] > second[1]
        np.testing.assert_allclose(spec.face_extent, [second[1], first[1]])


def test_make_object_overrides_only_masses():
    base = make_object("wedge")
    heavy = make_object("wedge", mass=0.42, pusher_mass=0.05)
    assert heavy.pusher_mass == 0.05
    np.testing.assert_array_equal(heavy.footprint, base.footprint)
    assert heavy.com_height == base.com_height
    assert heavy.inertia_z == pytest.approx(base.inertia_z * 0.42 / 0.35, rel=1e-12)
    np.testing.assert_allclose(heavy.support_loads, base.support_loads * 0.42 / 0.35)
    assert make_object("cube") is make_object("cube")
    assert resolve_object("wedge", mass=0.42) == ObjectSpec(
        "wedge", base.footprint, 0.42, base.height_at_origin, base.slope, 0.040
    )


def test_spec_is_frozen_and_arrays_read_only():
    cube = make_object("cube")
    with pytest.raises(dataclasses.FrozenInstanceError):
        cube.mass = 1.0  # type: ignore[misc]
    for array in (cube.footprint, cube.support_points, cube.support_loads, cube.slope):
        with pytest.raises(ValueError):
            array[0] = 0.0


# -------------------------------------------------------------------- mass properties


@pytest.mark.parametrize("seed", range(4))
def test_random_polygon_against_quadrature(seed):
    rng = np.random.default_rng(seed)
    vertices = random_convex_polygon(rng)
    slope = rng.normal(0.0, 0.3, 2) if seed % 2 else np.zeros(2)
    height = 0.01 - float((vertices @ slope).min()) + rng.uniform(0.0, 0.05)
    mass = rng.uniform(0.1, 1.0)
    spec = object_from_footprint("random", vertices, mass, height, slope=slope)
    volume, com, com_height, inertia = reference_mass_properties(vertices, height, slope, mass)
    assert spec.volume == pytest.approx(volume, rel=1e-9)
    assert spec.com_height == pytest.approx(com_height, rel=1e-9)
    assert spec.inertia_z == pytest.approx(inertia, rel=1e-9)
    # The local footprint is the given one moved rigidly so the CoM is at the origin.
    np.testing.assert_allclose(
        np.sort(np.hypot(*spec.footprint.T)), np.sort(np.hypot(*(vertices - com).T)), atol=1e-12
    )


@settings(max_examples=40, deadline=None, database=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    angle=st.floats(-math.pi, math.pi),
    shift=st.tuples(st.floats(-1.0, 1.0), st.floats(-1.0, 1.0)),
    clockwise=st.booleans(),
)
def test_rigid_motion_and_orientation_do_not_change_the_spec(seed, angle, shift, clockwise):
    rng = np.random.default_rng(seed)
    vertices = random_convex_polygon(rng, n_points=6)
    slope = rng.normal(0.0, 0.2, 2)
    height = 0.02 - float((vertices @ slope).min())
    face = int(rng.integers(len(vertices)))
    base = object_from_footprint("p", vertices, 0.3, height, slope=slope, pushed_face=face)

    c, s = math.cos(angle), math.sin(angle)
    rot = np.array([[c, -s], [s, c]])
    moved = vertices @ rot.T + shift
    moved_slope = rot @ slope  # h'(p') = h(Rᵀ(p' - t)) = h0 - (R g)·t + (R g)·p'
    moved_height = height - moved_slope @ np.asarray(shift)
    moved_face = face
    if clockwise:  # the user's edge i (i -> i+1) becomes edge V-2-i of the reversed list
        moved = moved[::-1]
        moved_face = (len(vertices) - 2 - face) % len(vertices)
    other = object_from_footprint(
        "p", moved, 0.3, moved_height, slope=moved_slope, pushed_face=moved_face
    )
    np.testing.assert_allclose(other.footprint, base.footprint, atol=1e-11)
    np.testing.assert_allclose(other.slope, base.slope, atol=1e-11)
    assert other.height_at_origin == pytest.approx(base.height_at_origin, abs=1e-11)
    assert other.inertia_z == pytest.approx(base.inertia_z, rel=1e-9)
    assert other.com_height == pytest.approx(base.com_height, rel=1e-9)
    np.testing.assert_allclose(other.support_loads, base.support_loads, atol=1e-8)


@pytest.mark.parametrize("seed", range(6))
def test_support_loads_balance_gravity(seed):
    rng = np.random.default_rng(100 + seed)
    vertices = random_convex_polygon(rng)
    slope = rng.normal(0.0, 0.3, 2)
    height = 0.005 - float((vertices @ slope).min())
    spec = object_from_footprint("p", vertices, rng.uniform(0.1, 2.0), height, slope=slope)
    loads, points = spec.support_loads, spec.support_points
    assert loads.min() >= 0.0
    assert abs(loads.sum() - spec.mass * GRAVITY) < 1e-9
    assert np.abs(loads @ points).max() < 1e-9  # moment about the CoM [N·m]


def test_support_loads_are_minimum_norm():
    # Six points around the CoM: compare with a generic constrained minimiser.
    from scipy.optimize import minimize

    points = [[-0.05, 0.03], [-0.05, -0.03], [0.0, -0.04], [0.06, -0.02], [0.06, 0.03], [0.0, 0.04]]
    spec = object_from_footprint("hex", points, 0.5, 0.05, support_points=points)
    local = spec.support_points
    weight = spec.mass * GRAVITY
    constraints = {"type": "eq", "fun": lambda n: [n.sum() - weight, *(n @ local)]}
    reference = minimize(
        lambda n: n @ n,
        np.full(6, weight / 6),
        bounds=[(0.0, None)] * 6,
        constraints=constraints,
        method="SLSQP",
        options={"ftol": 1e-15, "maxiter": 500},
    ).x
    np.testing.assert_allclose(spec.support_loads, reference, atol=1e-6)


def test_custom_support_points_on_an_edge_are_accepted():
    spec = object_from_footprint(
        "tri-support", SQUARE, 0.2, 0.05, support_points=[[0.0, 0.0], [0.1, 0.0], [0.05, 0.1]]
    )
    assert abs(spec.support_loads.sum() - 0.2 * GRAVITY) < 1e-12
    assert np.abs(spec.support_loads @ spec.support_points).max() < 1e-12


# ------------------------------------------------------------------------------ TOML


def test_toml_round_trip(tmp_path: Path):
    for name in OBJECT_NAMES:
        spec = make_object(name)
        path = tmp_path / f"{name}.toml"
        write_object(spec, path)
        loaded = load_object(path)
        assert loaded.name == spec.name
        assert loaded.mass == spec.mass and loaded.pusher_mass == spec.pusher_mass
        np.testing.assert_allclose(loaded.footprint, spec.footprint, atol=1e-15)
        np.testing.assert_allclose(loaded.support_loads, spec.support_loads, rtol=1e-12)
        assert loaded.inertia_z == pytest.approx(spec.inertia_z, rel=1e-12)
        assert resolve_object(str(path)).com_height == pytest.approx(spec.com_height)
        heavier = resolve_object(path, mass=2.0 * spec.mass, pusher_mass=0.05)
        assert heavier.pusher_mass == 0.05
        assert heavier.inertia_z == pytest.approx(2.0 * spec.inertia_z, rel=1e-12)


def test_user_toml_wedge_matches_preset(tmp_path: Path):
    path = tmp_path / "ramp.toml"
    # Clockwise, shifted, back face on x = 0.2: the default pushed face is the -x edge.
    # The height is given at the origin of these coordinates, 0.2 m behind the back face.
    slope = -0.08 / 0.14
    path.write_text(
        f'name = "ramp"\nmass = 0.35\npusher_mass = 0.04\n'
        f"height = {0.08 - 0.2 * slope!r}\nslope = [{slope!r}, 0.0]\n"
        "footprint = [[0.2, 0.0], [0.2, 0.085], [0.34, 0.085], [0.34, 0.0]]\n"
    )
    spec = resolve_object(path)
    wedge = make_object("wedge")
    assert spec.name == "ramp"
    np.testing.assert_allclose(spec.footprint, wedge.footprint, atol=1e-12)
    assert spec.inertia_z == pytest.approx(wedge.inertia_z, rel=1e-12)
    np.testing.assert_allclose(spec.support_loads, wedge.support_loads, rtol=1e-10)


def test_toml_size_key_builds_a_box(tmp_path: Path):
    path = tmp_path / "box.toml"
    path.write_text("mass = 0.3\nheight = 0.088\nsize = [0.088, 0.088]\n")
    spec = load_object(path)
    assert spec.name == "box"
    np.testing.assert_allclose(spec.footprint, make_object("cube").footprint, atol=1e-15)


def _one_line_config_error(call, *fragments: str) -> str:
    with pytest.raises(ConfigError) as info:
        call()
    message = str(info.value)
    assert "\n" not in message
    for fragment in fragments:
        assert fragment in message, message
    return message


def test_corrupt_and_missing_toml_files(tmp_path: Path):
    corrupt = tmp_path / "corrupt.toml"
    corrupt.write_text('mass = 0.3\nheight = [0.1,\nname = "x\n')
    _one_line_config_error(lambda: load_object(corrupt), str(corrupt), "line")
    missing = tmp_path / "nope.toml"
    _one_line_config_error(lambda: load_object(missing), str(missing), "does not exist")
    _one_line_config_error(lambda: resolve_object(str(missing)), "does not exist")
    binary = tmp_path / "binary.toml"
    binary.write_bytes(b"\xff\xfe\x00mass")
    _one_line_config_error(lambda: load_object(binary), str(binary))


@pytest.mark.parametrize(
    ("text", "fragment"),
    [
        ("mass = 0.3\nheight = 0.1\nsize = [0.1, 0.1]\ncolour = 1\n", "unknown key"),
        ("height = 0.1\nsize = [0.1, 0.1]\n", "missing key 'mass'"),
        ("mass = 0.3\nheight = 0.1\n", "exactly one of"),
        ("mass = 0.3\nheight = 0.1\nsize = [0.1, -0.1]\n", "positive"),
        ('mass = "heavy"\nheight = 0.1\nsize = [0.1, 0.1]\n', "mass must be a number"),
        ("mass = 0.3\nheight = 0.1\nsize = [0.1, 0.1]\npushed_face = 4\n", "out of range"),
    ],
)
def test_bad_toml_content(tmp_path: Path, text: str, fragment: str):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    _one_line_config_error(lambda: load_object(path), str(path), fragment)


# ------------------------------------------------------------------------ bad inputs


@pytest.mark.parametrize(
    ("kwargs", "fragments"),
    [
        ({"mass": 0.0}, ("mass", "positive")),
        ({"mass": -1.0}, ("mass", "positive")),
        ({"mass": float("nan")}, ("mass", "positive")),
        ({"pusher_mass": 0.0}, ("pusher_mass", "positive")),
        ({"height": 0.0}, ("height", "positive")),
        ({"height": -0.01}, ("negative",)),
        ({"slope": (-2.0, 0.0), "height": 0.1}, ("negative", "corner")),
        ({"slope": (1.0, 2.0, 3.0)}, ("slope",)),
        ({"slope": "uphill"}, ("slope", "[gx, gy]")),
        ({"height": "tall"}, ("height", "finite")),
        ({"pushed_face": 4}, ("pushed_face 4", "0..3")),
        ({"pushed_face": -1}, ("out of range",)),
        ({"footprint": [[0, 0], [1, 0]]}, ("at least 3",)),
        ({"footprint": [[0, 0], [1, 0], [2, 0], [3, 0]]}, ("degenerate",)),
        ({"footprint": [[0, 0], [1, 0], [1, 0], [0, 1]]}, ("vertex 2 repeats vertex 1",)),
        ({"footprint": [[0, 0], [0.1, 0], [0.03, 0.03], [0, 0.1]]}, ("not convex", "vertex 2")),
        ({"footprint": [[0, 0], [0.1, 0.1], [0.1, 0], [0, 0.1]]}, ("footprint",)),
        ({"footprint": [[0, 0], [0.05, 0], [0.1, 0], [0, 0.1]]}, ("vertex 1", "collinear")),
        ({"footprint": [[0, 0], [1, np.inf], [0, 1]]}, ("finite",)),
        ({"footprint": [0, 1, 2]}, ("[x, y] pairs",)),
        ({"support_points": [[0.01, 0.01], [0.02, 0.01], [0.01, 0.02]]}, ("infeasible",)),
        ({"support_points": [[0.0, 0.0], [0.5, 0.5]]}, ("outside the footprint",)),
    ],
)
def test_bad_inputs_raise_config_error(kwargs, fragments):
    args = {"footprint": SQUARE, "mass": 0.3, "height": 0.05} | kwargs
    footprint, mass, height = args.pop("footprint"), args.pop("mass"), args.pop("height")
    _one_line_config_error(
        lambda: object_from_footprint("bad", footprint, mass, height, **args), *fragments
    )


def test_self_intersecting_star_is_rejected():
    star = [
        [math.cos(4.0 * math.pi * k / 5.0), math.sin(4.0 * math.pi * k / 5.0)] for k in range(5)
    ]
    _one_line_config_error(lambda: object_from_footprint("star", star, 1.0, 0.1), "self-inter")


def test_unknown_name_lists_choices():
    message = _one_line_config_error(lambda: make_object("sphere"), "cube", "wedge", ".toml")
    assert "sphere" in message
    _one_line_config_error(lambda: resolve_object("pyramid"), "cube, wedge", ".toml")


def test_object_spec_checks_its_frame():
    cube = make_object("cube")
    _one_line_config_error(
        lambda: ObjectSpec("shifted", cube.footprint + 0.01, 0.3, 0.088), "local frame"
    )
    _one_line_config_error(
        lambda: ObjectSpec("cw", cube.footprint[::-1], 0.3, 0.088), "counter-clockwise"
    )
    _one_line_config_error(lambda: make_object("cube", mass=-0.3), "mass", "positive")


# -------------------------------------------------------------------------- geometry


def test_signed_distance_against_dense_boundary_sampling():
    rng = np.random.default_rng(7)
    for _ in range(5):
        vertices = random_convex_polygon(rng)
        spec = object_from_footprint("p", vertices, 0.3, 0.05)
        local = spec.footprint
        normals = spec.polygon.normals
        # Random points, plus points in every vertex region and on every edge's outer strip.
        centre = local.mean(axis=0)
        points = [centre + rng.uniform(-0.12, 0.12, size=(60, 2))]
        prev_normals = np.roll(normals, 1, axis=0)
        for w in rng.uniform(0.05, 0.95, 3):
            bisector = w * normals + (1.0 - w) * prev_normals
            points.append(local + rng.uniform(0.001, 0.03) * bisector)
        points.append(0.5 * (local + np.roll(local, -1, axis=0)) + 0.02 * normals)
        points.append(0.5 * (local + np.roll(local, -1, axis=0)) - 0.002 * normals)
        points = np.concatenate(points)
        ref_d, ref_closest = brute_force_distance(local, points)
        spacing = spec.polygon.lengths.max() / 4000
        for point, d_ref, c_ref in zip(points, ref_d, ref_closest, strict=True):
            d, normal, closest = signed_distance(spec, point)
            assert np.sign(d) == np.sign(d_ref)
            assert d == pytest.approx(d_ref, abs=spacing)
            assert np.linalg.norm(closest - c_ref) < 2.0 * spacing + 1e-6 * (abs(d) < 1e-3)
            assert np.linalg.norm(normal) == pytest.approx(1.0, abs=1e-12)
            # The closest point is on the boundary and the point sits on its normal ray.
            assert abs(signed_distance(spec, closest)[0]) < 1e-12
            np.testing.assert_allclose(point, closest + d * normal, atol=1e-12)
            if d <= 0.0:  # inside: the normal is the outward normal of one face
                assert np.min(np.linalg.norm(normals - normal, axis=1)) < 1e-12


def test_signed_distance_simple_cases():
    cube = make_object("cube")
    d, normal, closest = signed_distance(cube.footprint, np.array([-0.054, 0.01]))
    assert d == pytest.approx(0.01)
    np.testing.assert_allclose(normal, [-1.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(closest, [-0.044, 0.01], atol=1e-15)
    d, normal, _ = signed_distance(cube, (0.054, 0.054))  # vertex region: diagonal normal
    assert d == pytest.approx(0.01 * math.sqrt(2.0))
    np.testing.assert_allclose(normal, [math.sqrt(0.5), math.sqrt(0.5)])
    d, normal, closest = signed_distance(cube, (-0.040, 0.0))  # inside, near the pushed face
    assert d == pytest.approx(-0.004)
    np.testing.assert_allclose(normal, [-1.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(closest, [-0.044, 0.0], atol=1e-15)
    # A raw vertex list (either orientation) gives the same answer as the spec.
    d_raw, _, _ = signed_distance(cube.footprint[::-1].tolist(), (0.054, 0.054))
    assert d_raw == pytest.approx(0.01 * math.sqrt(2.0))


@settings(max_examples=60, deadline=None, database=None)
@given(st.lists(st.tuples(st.floats(-0.2, 0.2), st.floats(-0.2, 0.2)), min_size=1, max_size=4))
def test_batch_matches_single_calls(points):
    wedge = make_object("wedge")
    distances, normals, closest = signed_distance_batch(wedge, np.array(points))
    for i, point in enumerate(points):
        d, n, c = signed_distance(wedge, point)
        assert distances[i] == d
        np.testing.assert_array_equal(normals[i], n)
        np.testing.assert_array_equal(closest[i], c)


def test_frame_transforms():
    wedge = make_object("wedge")
    pose = (0.4, -0.1, 0.7)
    rng = np.random.default_rng(3)
    points = rng.normal(size=(5, 2))
    np.testing.assert_allclose(to_local(pose, to_world(pose, points)), points, atol=1e-15)
    np.testing.assert_allclose(to_world(pose, [0.0, 0.0]), [0.4, -0.1])
    world = polygon_world(wedge, pose)
    np.testing.assert_allclose(world, to_world(pose, wedge.footprint))
    np.testing.assert_allclose(polygon_world(wedge, (0.0, 0.0, 0.0)), wedge.footprint)
    # At theta = pi/2 the push direction e_n points along world +y.
    np.testing.assert_allclose(
        vectors_to_world((1.0, 2.0, math.pi / 2), [1.0, 0.0]), [0, 1], atol=1e-15
    )
    vectors = rng.normal(size=(3, 2))
    np.testing.assert_allclose(vectors_to_local(pose, vectors_to_world(pose, vectors)), vectors)
    # Distances are frame-invariant: query a world point through to_local.
    point_world = np.array([0.3, -0.12])
    d, normal, closest = signed_distance(wedge, to_local(pose, point_world))
    assert np.linalg.norm(point_world - to_world(pose, closest)) == pytest.approx(abs(d))

    @dataclasses.dataclass
    class Pose:
        x: float
        y: float
        theta: float

    np.testing.assert_allclose(to_world(Pose(*pose), points), to_world(pose, points))
