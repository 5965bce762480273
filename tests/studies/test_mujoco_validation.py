"""Cross-engine validation (studies.mujoco_validation): MuJoCo against physics and ours."""

import math

import pytest

from pushctl.config import GRAVITY
from pushctl.engines import ENGINES
from studies import mujoco_validation as validation


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("heading_deg", [0.0, 45.0, 120.0])
def test_free_slide_within_10_percent_of_v0_squared_over_2_mu_g(engine, heading_deg):
    result = validation.free_slide(engine, heading_deg)
    assert result["distance"] == pytest.approx(result["expected"], rel=0.10)
    assert result["direction_error"] < math.radians(0.5)
    assert abs(result["theta"]) < 1e-3


@pytest.mark.parametrize("engine", ENGINES)
def test_free_slide_of_the_wedge_mesh(engine):
    result = validation.free_slide(engine, -30.0, obj="wedge")
    assert result["distance"] == pytest.approx(result["expected"], rel=0.10)


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize(("omega0", "dt"), validation.SPIN_CASES)
def test_spin_down_to_the_torsional_friction_angle(engine, omega0, dt):
    result = validation.spin_down(engine, omega0, dt)
    tolerance = 0.10 if dt < 0.01 else 0.15  # ours stops ~h·ω0/2 short at 0.01 s
    assert result["angle"] == pytest.approx(result["expected"], rel=tolerance)
    assert result["drift"] < 1e-4  # symmetric: no net force


def test_mujoco_object_rests_without_creep():
    result = validation.rest("mujoco", obj="wedge", seconds=2.0)
    assert result["drift"] < 1e-5
    assert 0.0 < result["sink"] < 1e-3


@pytest.mark.parametrize("engine", ENGINES)
def test_straight_push_cruise_force_is_mu_g_m_g(engine):
    result = validation.straight_push(engine)
    assert result["expected"] == pytest.approx(0.3 * 0.3 * GRAVITY)
    assert result["mean"] == pytest.approx(result["expected"], rel=0.10)
    assert result["min"] > 0.9 * result["expected"]  # no hopping or contact loss
    assert result["max"] < 1.1 * result["expected"]
    assert result["penetration"] < 1e-3
    assert result["distance"] == pytest.approx(0.20, abs=2e-3)


def _check_arc(obj, profile):
    result = validation.arc_push(obj, profile)
    assert result["rms_position"] < 2e-3
    assert result["final_angle"] < math.radians(0.5)
    assert result["penetration_mujoco"] < 1e-3
    assert result["force_error_mujoco"] < 0.1
    assert result["translation_error_mujoco"] < 1.0


def test_planned_arc_push_agrees_across_engines():
    _check_arc("cube", "constant")


@pytest.mark.slow
@pytest.mark.parametrize(
    ("obj", "profile"),
    [
        (o, p)
        for o in validation.OBJECTS
        for p in validation.PROFILES
        if (o, p) != ("cube", "constant")
    ],
)
def test_every_planned_arc_push_agrees_across_engines(obj, profile):
    _check_arc(obj, profile)


def test_generated_block_replaces_only_itself():
    block = f"{validation.BEGIN}\nnew\n{validation.END}\n"
    page = f"# title\n{validation.BEGIN}\nold\n{validation.END}\nafter\n"
    assert validation.replace_block(page, block) == f"# title\n{block}after\n"
    assert validation.replace_block("# t\n", block) == f"# t\n\n{block}"
