"""Angular profiles s(τ) (docs/design.md §4): boundary values, monotonicity, analytic derivatives,
mean rate, and the shape each profile promises (trapezoid cruise rate, rising chirp)."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pushctl.errors import ConfigError
from pushctl.planning.profiles import (
    PROFILE_NAMES,
    ChirpProfile,
    ConstantProfile,
    TrapezoidProfile,
    make_profile,
)

N_GRID = 4001
TAU = np.linspace(0.0, 1.0, N_GRID)
STEP = TAU[1] - TAU[0]


def cumulative_trapezoid(values: np.ndarray, step: float) -> np.ndarray:
    """∫_0^τ values dτ on the uniform grid, same length as ``values``."""
    return np.concatenate([[0.0], np.cumsum(0.5 * step * (values[1:] + values[:-1]))])


def away_from(tau: np.ndarray, kinks) -> np.ndarray:
    """Mask of grid points more than 3 steps from every kink."""
    mask = np.ones_like(tau, dtype=bool)
    for k in kinks:
        mask &= np.abs(tau - k) > 3 * STEP
    return mask


def third_derivative_bound(values: np.ndarray, kinks) -> float:
    """max |f'''| estimated from third differences of f away from the kinks (×2 margin)."""
    third = np.diff(values, 3) / STEP**3
    mask = away_from(TAU[1:-2], kinks)
    return 2.0 * float(np.abs(third[mask]).max(initial=0.0)) + 1e-6


def check_profile_invariants(profile, kinks=()):
    """The properties every profile shares, on a dense grid; ``kinks`` are τ where dds
    jumps (excluded from the finite-difference check of dds)."""
    s, ds, dds = profile.evaluate(TAU)
    assert s.shape == ds.shape == dds.shape == TAU.shape
    assert np.all(np.isfinite(s)) and np.all(np.isfinite(ds)) and np.all(np.isfinite(dds))
    # end points, exactly (scalars too)
    s0, _, _ = profile.evaluate(np.array([0.0]))
    s1, _, _ = profile.evaluate(np.array([1.0]))
    assert abs(s0[0]) <= 1e-12
    assert abs(s1[0] - 1.0) <= 1e-12
    # non-negative rate and monotone s
    assert ds.min() >= -1e-12
    assert np.all(np.diff(s) >= -1e-12)
    # ds is the derivative of s: integrating ds reproduces s (trapezoid-rule error at most
    # STEP²/12 · max|s'''| per unit length) and central differences of s reproduce ds
    # (error at most STEP²/6 · max|s'''|); max|s'''| is estimated from s alone, not from dds.
    s3 = third_derivative_bound(s, kinks)
    jump = 2.0 * float(np.abs(dds).max())  # bound on a jump of dds at a kink
    np.testing.assert_allclose(
        cumulative_trapezoid(ds, STEP),
        s,
        rtol=0,
        atol=1e-12 + STEP**2 * (s3 / 6 + len(kinks) * jump / 4),
    )
    away = away_from(TAU[1:-1], kinks)
    fd_ds = (s[2:] - s[:-2]) / (2 * STEP)
    np.testing.assert_allclose(fd_ds[away], ds[1:-1][away], rtol=0, atol=1e-9 + STEP**2 * s3 / 3)
    # dds is the derivative of ds: by integration everywhere (a jump in dds costs at most
    # STEP·|jump| locally) and by central differences away from the kinks
    ds3 = third_derivative_bound(ds, kinks)
    np.testing.assert_allclose(
        cumulative_trapezoid(dds, STEP) + ds[0],
        ds,
        rtol=0,
        atol=1e-12 + STEP**2 * ds3 / 6 + len(kinks) * STEP * jump,
    )
    fd_dds = (ds[2:] - ds[:-2]) / (2 * STEP)
    np.testing.assert_allclose(fd_dds[away], dds[1:-1][away], rtol=0, atol=1e-9 + STEP**2 * ds3 / 3)
    # mean rate is 1 (∫ds = s(1) − s(0) = 1)
    mean_tol = 1e-12 + STEP**2 * (s3 / 6 + len(kinks) * jump / 4)
    assert cumulative_trapezoid(ds, STEP)[-1] == pytest.approx(1.0, abs=mean_tol)
    return s, ds, dds


# --------------------------------------------------------------------- constant


def test_constant_profile_is_identity():
    profile = make_profile("constant")
    assert isinstance(profile, ConstantProfile) and profile.name == "constant"
    s, ds, dds = check_profile_invariants(profile)
    np.testing.assert_array_equal(s, TAU)
    np.testing.assert_array_equal(ds, 1.0)
    np.testing.assert_array_equal(dds, 0.0)


def test_evaluate_does_not_alias_its_input():
    tau = np.linspace(0, 1, 5)
    s, _, _ = make_profile("constant").evaluate(tau)
    s[:] = 7.0
    np.testing.assert_array_equal(tau, np.linspace(0, 1, 5))


# -------------------------------------------------------------------- trapezoid


def check_trapezoid(a: float, d: float):
    profile = make_profile("trapezoid", accel_fraction=a, decel_fraction=d)
    assert isinstance(profile, TrapezoidProfile) and profile.name == "trapezoid"
    s, ds, dds = check_profile_invariants(profile, kinks=(a, 1.0 - d))
    rate = 2.0 / (2.0 - a - d)
    assert profile.cruise_rate == pytest.approx(rate, rel=1e-15)
    # cruise phase: constant rate 2/(2−a−d), no acceleration
    cruise = (TAU > a + 2 * STEP) & (TAU < 1.0 - d - 2 * STEP)
    if cruise.any():
        np.testing.assert_allclose(ds[cruise], rate, rtol=1e-14)
        np.testing.assert_array_equal(dds[cruise], 0.0)
    # ramps: uniform acceleration rate/a and deceleration −rate/d
    if a > 0:
        rising = TAU < a - 2 * STEP
        np.testing.assert_allclose(dds[rising], rate / a, rtol=1e-14)
        assert ds[0] == 0.0  # starts at rest
    else:
        assert ds[0] == pytest.approx(rate, rel=1e-14)  # a step in rate at the start
    if d > 0:
        falling = TAU > 1.0 - d + 2 * STEP
        np.testing.assert_allclose(dds[falling], -rate / d, rtol=1e-14)
        assert ds[-1] == pytest.approx(0.0, abs=1e-12)  # ends at rest
    else:
        assert ds[-1] == pytest.approx(rate, rel=1e-14)
    # the peak rate is the cruise rate (never exceeded)
    assert ds.max() <= rate * (1 + 1e-14)


@pytest.mark.parametrize(
    ("a", "d"),
    [(0.25, 0.25), (0.0, 0.0), (0.0, 0.3), (0.4, 0.0), (0.5, 0.5), (1.0, 0.0), (0.1, 0.7)],
)
def test_trapezoid_fixed_fractions(a, d):
    check_trapezoid(a, d)


def test_trapezoid_defaults():
    profile = make_profile("trapezoid")
    assert (profile.accel_fraction, profile.decel_fraction) == (0.25, 0.25)
    assert profile.cruise_rate == pytest.approx(4.0 / 3.0)
    check_trapezoid(0.25, 0.25)


def test_trapezoid_with_zero_fractions_equals_constant():
    s, ds, dds = make_profile("trapezoid", accel_fraction=0.0, decel_fraction=0.0).evaluate(TAU)
    np.testing.assert_allclose(s, TAU, atol=1e-15)
    np.testing.assert_allclose(ds, 1.0, atol=1e-15)
    np.testing.assert_array_equal(dds, 0.0)


@settings(max_examples=40, deadline=None)
@given(
    a=st.one_of(st.just(0.0), st.just(1.0), st.floats(1e-3, 1.0)),
    share=st.one_of(st.just(0.0), st.just(1.0), st.floats(0.0, 1.0)),
)
def test_trapezoid_random_fractions(a, share):
    d = share * (1.0 - a)  # a + d ≤ 1
    if d < 1e-3:
        d = 0.0  # tiny ramps are tested separately
    check_trapezoid(a, d)


@pytest.mark.parametrize("tiny", [5e-324, 1e-310, 1e-300, 1e-12, 1e-9])
@pytest.mark.parametrize("which", ["accel_fraction", "decel_fraction"])
def test_trapezoid_tiny_ramp_is_rejected_or_finite(tiny, which):
    """A ramp shorter than any grid step must either be refused or stay finite: rate/a
    overflows to inf for a subnormal fraction, which would poison a plan's forces."""
    try:
        profile = make_profile("trapezoid", **{which: tiny})
    except ConfigError:
        return
    s, ds, dds = profile.evaluate(np.array([0.0, 0.5, 1.0]))
    assert np.all(np.isfinite(s)) and np.all(np.isfinite(ds)) and np.all(np.isfinite(dds))


# ------------------------------------------------------------------------ chirp


def local_maxima(values: np.ndarray) -> np.ndarray:
    inner = (values[1:-1] > values[:-2]) & (values[1:-1] >= values[2:])
    return np.flatnonzero(inner) + 1


def check_chirp(f0: float, f1: float, depth: float):
    profile = make_profile("chirp", start_cycles=f0, end_cycles=f1, depth=depth)
    assert isinstance(profile, ChirpProfile) and profile.name == "chirp"
    s, ds, dds = check_profile_invariants(profile)
    # the deepest dip is no lower than 1 − depth of the mean rate
    assert ds.min() >= 1.0 - depth - 1e-12
    return s, ds, dds


def test_chirp_default_oscillates_about_one_with_rising_frequency():
    profile = make_profile("chirp")
    assert (profile.start_cycles, profile.end_cycles, profile.depth) == (1.0, 4.0, 0.8)
    _, ds, _ = check_chirp(1.0, 4.0, 0.8)
    # oscillates about its mean 1: well above and well below it, crossing it many times
    assert ds.max() > 1.5 and ds.min() < 0.5
    crossings = np.count_nonzero(np.diff(np.sign(ds - 1.0)) != 0)
    # 1 → 4 cycles per push: 2.5 cycles, 2 crossings each
    assert crossings >= 4
    # the last dip: cos φ = 1 at φ = 4π, i.e. τ* = (√13 − 1)/3, where
    # ds = 1 − B φ'(τ*) = 1 − depth (1 + 3τ*)/4 ≈ 0.279 (B = depth / (8π) since sin 5π = 0);
    # the bound 1 − depth = 0.2 is conservative
    tau_star = (math.sqrt(13.0) - 1.0) / 3.0
    dip = 1.0 - 0.8 * (1.0 + 3.0 * tau_star) / 4.0
    assert profile.evaluate(np.array([tau_star]))[1][0] == pytest.approx(dip, abs=1e-12)
    assert 0.2 <= ds.min() <= dip
    assert ds.min() == pytest.approx(dip, abs=2e-3)
    peaks = TAU[local_maxima(ds)]
    assert len(peaks) >= 2
    gaps = np.diff(peaks)
    assert np.all(np.diff(gaps) < 0), f"peak spacings do not shrink: {gaps}"
    # spacing ≈ 1/f(τ) with f rising from 1 to 4 cycles per push
    assert gaps[-1] < 0.5 * gaps[0] or len(gaps) == 1


def test_chirp_zero_depth_is_constant():
    s, ds, dds = make_profile("chirp", depth=0.0).evaluate(TAU)
    np.testing.assert_allclose(s, TAU, atol=1e-15)
    np.testing.assert_allclose(ds, 1.0, atol=1e-15)
    np.testing.assert_allclose(dds, 0.0, atol=1e-15)


def test_chirp_full_depth_touches_zero_but_never_goes_below():
    _, ds, _ = check_chirp(1.0, 4.0, 1.0)
    assert ds.min() >= -1e-12
    tau_star = (math.sqrt(13.0) - 1.0) / 3.0  # see the default test
    assert ds.min() == pytest.approx(1.0 - (1.0 + 3.0 * tau_star) / 4.0, abs=2e-3)
    # 1 → 3 cycles: φ(1) = 4π, so the push ends on a dip at the peak frequency, where the
    # bound is tight and depth 1 brings the rate exactly to 0
    _, ds, _ = check_chirp(1.0, 3.0, 1.0)
    assert ds[-1] == pytest.approx(0.0, abs=1e-12)
    assert ds.min() >= -1e-12


@settings(max_examples=30, deadline=None)
@given(
    f0=st.floats(0.5, 3.0),
    extra=st.floats(1.0, 5.0),
    depth=st.floats(0.05, 1.0),
)
def test_chirp_random_parameters(f0, extra, depth):
    f1 = f0 + extra
    _, ds, _ = check_chirp(f0, f1, depth)
    # oscillates about its mean of 1
    assert ds.max() > 1.0 and ds.min() < 1.0
    peaks = TAU[local_maxima(ds)]
    if len(peaks) >= 3:
        gaps = np.diff(peaks)
        assert np.all(np.diff(gaps) < 2 * STEP), f"peak spacings do not shrink: {gaps}"
        assert gaps[-1] < gaps[0]


@settings(max_examples=15, deadline=None)
@given(f0=st.floats(0.5, 4.0), depth=st.floats(0.0, 1.0))
def test_chirp_equal_frequencies_is_still_valid(f0, depth):
    check_chirp(f0, f0, depth)


# ------------------------------------------------------------------------ errors


@pytest.mark.parametrize(
    ("name", "parameters"),
    [
        ("trapezoid", {"accel_fraction": -0.1}),
        ("trapezoid", {"decel_fraction": -1e-6}),
        ("trapezoid", {"accel_fraction": 0.6, "decel_fraction": 0.5}),
        ("trapezoid", {"accel_fraction": 1.5, "decel_fraction": 0.0}),
        ("trapezoid", {"accel_fraction": math.nan}),
        ("chirp", {"start_cycles": 4.0, "end_cycles": 1.0}),
        ("chirp", {"depth": 1.01}),
        ("chirp", {"depth": -0.1}),
        ("chirp", {"start_cycles": 0.0}),
        ("chirp", {"end_cycles": math.inf}),
        ("constant", {"depth": 0.5}),
        ("trapezoid", {"cycles": 1.0}),
        ("linear", {}),
        ("Constant", {}),
        ("", {}),
    ],
)
def test_bad_parameters_raise_config_error(name, parameters):
    with pytest.raises(ConfigError):
        make_profile(name, **parameters)


def test_unknown_profile_message_lists_the_choices():
    with pytest.raises(ConfigError) as info:
        make_profile("sine")
    for name in PROFILE_NAMES:
        assert name in str(info.value)
