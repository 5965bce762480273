"""The kinematic pusher against what it must agree with: Coulomb's law at the ground and at
the prong, the ellipsoidal limit surface's turning, the prong's radius, the pose frame."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pushctl.errors import ConfigError
from pushctl.kinematic import (
    GRAVITY,
    Friction,
    KinematicPushWorld,
    PressurePrior,
    Pusher,
    Slider,
    push_along,
    straight_path,
)

SQUARE = np.array([(-0.045, -0.045), (0.045, -0.045), (0.045, 0.045), (-0.045, 0.045)])
MASS = 0.8


def _push(pusher, path, friction, dt=0.05, shape=SQUARE, pose=(0.0, 0.0, 0.0)):
    slider = Slider.from_vertices(shape, MASS)
    world = KinematicPushWorld(slider, pusher, friction, dt)
    world.reset(pose)
    reports = []
    for a, b in zip(path[:-1], path[1:], strict=True):
        reports.append(world.step(a, b))
    return world, reports


@pytest.mark.parametrize("model", ["slip_box", "polygon", "axis_box"])
def test_centred_push_slides_straight_at_mu_g_m_g(model):
    pusher = Pusher.row(2, 0.04, 4.75e-3)
    start = -0.045 - 4.75e-3
    path = straight_path((start, 0, 0), (start + 0.03, 0, 0), speed=0.02, dt=0.05)
    world, reports = _push(pusher, path, Friction(0.3, 0.3, model))
    assert abs(world.pose[2]) < 1e-6 and abs(world.pose[1]) < 1e-6
    assert world.pose[0] == pytest.approx(0.03, abs=5e-4)
    push_force = np.mean([r.normal_force.sum() for r in reports[5:]])
    expected = 0.3 * MASS * GRAVITY
    if model == "polygon":
        # the regular octagon's support along one of its segments' directions: 5 % short of
        # the circle's (its support ranges over 0.95-1.03 of it)
        expected *= math.pi / 8 * sum(abs(math.cos(j * math.pi / 4)) for j in range(4))
        assert expected == pytest.approx(0.3 * MASS * GRAVITY, rel=0.06)
    assert push_force == pytest.approx(expected, rel=0.01)


@pytest.mark.parametrize("model", [("polygon", 16), ("polygon", 32)])
@pytest.mark.parametrize("offset", [0.03, -0.025])
def test_off_centre_push_turns_as_the_ellipsoidal_limit_surface_predicts(offset, model):
    a, v, heading = 0.045, 0.01, math.radians(10.0)
    slider = Slider.from_vertices(SQUARE, MASS)
    # c = m_max / f_max for this support: the load-weighted mean lever arm
    c = float((slider.loads * np.linalg.norm(slider.supports, axis=1)).sum() / slider.loads.sum())
    predicted_rate = -offset * v / (c**2 + a**2 + offset**2)  # a sticking point push
    c_h, s_h = math.cos(heading), math.sin(heading)
    turn = np.array([[c_h, -s_h], [s_h, c_h]])
    start, end = turn @ (-a - 4.75e-3, offset), turn @ (-a + 0.005, offset)
    path = straight_path((*start, heading), (*end, heading), v, dt=0.1)
    slider_world = KinematicPushWorld(slider, Pusher(), Friction(1.0, 0.3, *model), 0.1)
    slider_world.reset((0.0, 0.0, heading))
    rates = []
    for p0, p1 in zip(path[:-2], path[1:-1], strict=True):
        slider_world.step(p0, p1)
        rates.append(slider_world.velocity[2])
    rate = float(np.median(rates))
    assert np.sign(rate) == np.sign(predicted_rate)
    # the ellipsoid approximates this support's limit surface to within about a quarter
    assert rate == pytest.approx(predicted_rate, rel=0.3)


@pytest.mark.parametrize("model", ["polygon"])
def test_prong_sticks_inside_the_cone_and_slides_at_its_edge(model):
    pusher = Pusher.row(2, 0.04, 4.75e-3)
    start = np.array((-0.045 - 4.75e-3, 0.0, 0.0))
    for slope, mu, sticks in ((0.1, 0.5, True), (1.0, 0.3, False)):
        end = start + (0.02, 0.02 * slope, 0.0)
        path = straight_path(start, end, speed=0.02, dt=0.05)
        slider = Slider.from_vertices(SQUARE, MASS)
        world = KinematicPushWorld(slider, pusher, Friction(mu, 0.3, model), 0.05)
        world.reset((0.0, 0.0, 0.0))
        ratios, along_face = [], []
        for k, (a, b) in enumerate(zip(path[:-1], path[1:], strict=True)):
            report = world.step(a, b)
            # the split between the two prongs is not unique: their total obeys the cone
            if k >= 5:
                ratios.append(abs(report.tangential_force.sum()) / report.normal_force.sum())
                along_face.append(_in_object_frame(world, pusher.prong_positions(b)[0])[1])
        slip = abs(along_face[-1] - along_face[0])  # the prong's travel along the face [m]
        if sticks:
            assert max(ratios) < mu - 1e-3 and slip < 1e-5
        else:
            assert ratios == pytest.approx([mu] * len(ratios), rel=1e-6) and slip > 1e-3


def _in_object_frame(world, point):
    c, s = math.cos(world.pose[2]), math.sin(world.pose[2])
    d = np.asarray(point) - world.pose[:2]
    return np.array((c * d[0] + s * d[1], -s * d[0] + c * d[1]))


@pytest.mark.parametrize("radius", [1e-3, 4.75e-3, 12e-3])
def test_round_prong_touches_at_its_radius(radius):
    path = straight_path((-0.06 - radius, 0.01, 0), (-0.02, 0.01, 0), 0.02, 0.05)
    world, reports = _push(Pusher(radius=radius), path, Friction(0.3, 0.3, "polygon"))
    assert reports[-1].normal_force[0] > 0
    local = _in_object_frame(world, path[-1, :2])
    gap = world.slider.polygon.query(*(local - world.slider.centroid))[0]
    assert gap == pytest.approx(radius, abs=2e-4)


def test_the_pose_frame_need_not_be_the_centroid():
    triangle = np.array([(0.045, -0.08), (0.045, 0.045), (-0.08, 0.045)])
    shift = np.array((0.03, -0.02))
    path = straight_path((0.05, -0.04, math.pi), (0.01, -0.04, math.pi), 0.02, 0.05)
    kw = {"dt": 0.05, "mass": MASS, "friction": Friction(model="polygon")}
    a = push_along(triangle, path, object_pose=(0, 0, 0), **kw).poses[-1]
    # The same plate described in a frame moved by `shift`, placed where it was.
    b = push_along(triangle - shift, path, object_pose=(*shift, 0.0), **kw)
    end = b.poses[-1]
    c, s = math.cos(end[2]), math.sin(end[2])
    origin = end[:2] - np.array((c * shift[0] - s * shift[1], s * shift[0] + c * shift[1]))
    assert np.allclose(origin, a[:2], atol=1e-6) and end[2] == pytest.approx(a[2], abs=1e-6)
    assert abs(a[2]) > 0.01  # it did turn


def test_the_support_prior_carries_the_weight_about_the_centroid():
    triangle = np.array([(0.045, -0.13), (0.045, 0.045), (-0.08, 0.045)])
    for rim in (-2.0, 0.0, 2.0):
        slider = Slider.from_vertices(triangle, 1.3, PressurePrior(25, rim))
        assert slider.loads.sum() == pytest.approx(1.3 * GRAVITY)
        assert np.allclose(slider.loads @ slider.supports, 0.0, atol=1e-12)
        assert abs(len(slider.supports) - 25) <= 3


def test_bad_arguments_raise_config_errors():
    with pytest.raises(ConfigError):
        Pusher(radius=-1.0)
    with pytest.raises(ConfigError):
        Friction(model="cone")
    with pytest.raises(ConfigError):
        Friction(facets=6)
    with pytest.raises(ConfigError):
        Friction(model="polygon", facets=10)
    with pytest.raises(ConfigError):
        push_along(SQUARE, np.zeros((1, 3)), object_pose=(0, 0, 0), dt=0.05)
    with pytest.raises(ConfigError):
        Slider.from_vertices(SQUARE, mass=0.0)
