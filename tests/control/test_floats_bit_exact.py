"""The feedback law and the reference offset compute on Python floats (for speed: they run at
every 10 ms step); these tests hold the numpy forms they replaced and check the new ones
against them bit for bit, over long random sequences that take every branch: the lag, the
integral frozen off contact, the contact seek, both caps, the slide guard, the offset bound.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from pushctl.control.feedback import FeedbackGains, FeedbackLaw
from pushctl.control.residual import ReferenceOffset

PRONGS = np.array([-0.035, 0.035])
LEVER = np.array([-0.0325, 0.0021])


class NumpyLaw:
    """FeedbackLaw's arithmetic on numpy arrays, as it was before the floats."""

    def __init__(self, gains: FeedbackGains, lever: np.ndarray, dt: float, prongs: np.ndarray):
        self.gains, self.lever, self.dt, self.prongs = gains, lever.copy(), dt, prongs.copy()
        self._reach = float(np.max(np.abs(self.lever[1] + self.prongs)))
        self.integral, self.output = np.zeros(3), np.zeros(3)
        self.seeking_for, self.slide_now, self.since_landing = 0.0, None, 0.0
        self.landed = None

    def twist(self, error, normal_forces, speed, offset):
        raw = self._law(error, normal_forces, speed, offset)
        tau = self.gains.smoothing
        if tau <= 0.0:
            return raw
        self.output = self.output + (self.dt / (tau + self.dt)) * (raw - self.output)
        return self.output.copy()

    def _law(self, error, normal_forces, speed, offset):
        gains = self.gains
        error = np.asarray(error, dtype=float)
        loaded = np.asarray(normal_forces) >= gains.contact_force
        all_loaded = bool(loaded.all())
        seeking = not all_loaded and bool(loaded.any())
        self.seeking_for = self.seeking_for + self.dt if seeking else 0.0
        slid = 0.0
        if offset is not None and math.isfinite(gains.slide_limit):
            now = float(offset[1] + error[1] + error[2] * self.lever[0])
            if self.slide_now is None:
                if all_loaded:
                    self.slide_now, self.since_landing = now, 0.0
            else:
                tau = gains.slide_filter
                self.slide_now += (self.dt / (tau + self.dt)) * (now - self.slide_now)
                self.since_landing += self.dt
                if self.landed is None and self.since_landing >= 2.0 * tau:
                    self.landed = self.slide_now
            if self.landed is not None and self.slide_now is not None:
                slid = self.slide_now - self.landed
        guarded = abs(slid) >= gains.slide_limit
        if all_loaded:
            step = self.dt * error
            if guarded and step[1] * slid > 0.0:
                step[1] = 0.0
            self.integral = self.integral + step
        elif gains.hold_off_contact:
            if seeking and gains.seek_rate > 0.0:
                centre = float(np.mean(self.prongs[loaded]))
                free = self.prongs[~loaded]
                farthest = float(free[np.argmax(np.abs(free - centre))])
                ramp = gains.seek_ramp
                rate = gains.seek_rate * (min(1.0, self.seeking_for / ramp) if ramp > 0 else 1.0)
                omega = -math.copysign(rate, farthest - centre)
                return np.array([omega * centre, 0.0, omega])
            return np.zeros(3)
        u = gains.k * error + gains.k_i * self.integral
        r_x, r_y = self.lever
        cap = gains.turn_ratio * abs(speed) / self._reach
        u[2] = min(max(u[2], -cap), cap)
        lateral = u[1] + u[2] * r_x
        cap = gains.lateral_ratio * abs(speed)
        lateral = min(max(lateral, -cap), cap)
        if guarded and lateral * slid > 0.0:
            lateral = 0.0
        return np.array([u[0] - u[2] * r_y, lateral, u[2]])


def numpy_shifted(offset, limit, dt, position, yaw, twist_ff, residual):
    """ReferenceOffset.shifted's arithmetic on numpy arrays: (position, yaw, twist, offset)."""
    shifted_position = position.copy()
    shifted_position[0] += offset[0]
    shifted_position[1] += offset[1]
    shifted_yaw = float(yaw) + float(offset[2])
    advanced = offset + dt * residual
    if limit is not None:
        clipped = np.clip(advanced, -limit, limit)
        residual = np.where(clipped == advanced, residual, (clipped - offset) / dt)
        advanced = clipped
    twist = twist_ff.copy()
    twist[0] += residual[0]
    twist[1] += residual[1]
    twist[5] += residual[2]
    return shifted_position, shifted_yaw, twist, advanced


def _bits(values) -> bytes:
    return np.asarray(values, dtype=np.float64).tobytes()


@pytest.mark.parametrize(
    "gains",
    [
        FeedbackGains(k=1.0, k_i=0.1),  # the shipped law's gains, with its lag and caps
        FeedbackGains(k=11.3, k_i=40.0, smoothing=0.0, slide_limit=5e-4, slide_filter=0.2),
        FeedbackGains(k=3.0, k_i=2.0, hold_off_contact=False, seek_ramp=0.0),
    ],
)
def test_the_float_law_is_the_numpy_law_bit_for_bit(gains: FeedbackGains) -> None:
    rng = np.random.default_rng(7)
    law, reference = FeedbackLaw(gains, LEVER, 0.01, PRONGS), NumpyLaw(gains, LEVER, 0.01, PRONGS)
    branches = set()
    for _ in range(3000):
        # float32 inputs, as the observation rounds them; normal forces about the threshold
        error = (rng.normal(size=3) * [2e-3, 2e-3, 0.03]).astype(np.float32).astype(float)
        forces = rng.choice([0.0, 0.04, 0.05, 0.3], size=2) + rng.normal(size=2) * 0.005
        speed = float(abs(rng.normal()) * 0.01)
        offset = rng.normal(size=3) * [1e-3, 1e-3, 0.01]
        new = law.twist(error, forces, speed, offset)
        old = reference.twist(error, forces, speed, offset)
        assert _bits(new) == _bits(old)
        assert _bits(law.integral) == _bits(reference.integral)
        branches.add((bool((forces >= 0.05).all()), bool((forces >= 0.05).any())))
    assert len(branches) == 3  # all loaded, some (the seek), none


def test_the_float_offset_is_the_numpy_offset_bit_for_bit_also_where_it_is_clipped() -> None:
    rng = np.random.default_rng(3)
    limit = (0.003, math.radians(3.0))
    offset, dt = ReferenceOffset(0.01, limit), 0.01
    reference = np.zeros(3)
    bound = np.array([limit[0], limit[0], limit[1]])
    clipped = 0
    for n in range(4000):
        position, yaw = rng.normal(size=3), float(rng.normal())
        twist_ff = rng.normal(size=6) * 0.01
        residual = None if n % 7 == 0 else rng.normal(size=3) * [0.01, 0.01, 0.1]
        got = offset.shifted(position, yaw, twist_ff, residual)
        if residual is None:
            expected = numpy_shifted(reference, bound, dt, position, yaw, twist_ff, np.zeros(3))
            assert _bits(got[0]) == _bits(expected[0]) and got[1] == expected[1]
            assert got[2] is twist_ff
            continue
        expected = numpy_shifted(reference, bound, dt, position, yaw, twist_ff, residual)
        clipped += bool(np.any(np.abs(expected[3]) == bound))
        reference = expected[3]
        assert _bits(got[0]) == _bits(expected[0])
        assert got[1] == expected[1]
        assert _bits(got[2]) == _bits(expected[2])
        assert _bits(offset.offset) == _bits(reference)
    assert clipped > 100  # the bound was reached often


def test_the_offset_set_from_outside_is_read_back_as_given() -> None:
    offset = ReferenceOffset(0.01)
    offset.offset = np.array([1e-3, -2e-3, 0.01])
    np.testing.assert_array_equal(offset.offset, [1e-3, -2e-3, 0.01])
    offset.reset()
    np.testing.assert_array_equal(offset.offset, np.zeros(3))
