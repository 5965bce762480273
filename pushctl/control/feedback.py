"""The ``feedback`` baseline's law (docs/design.md §5): a PI law on the object's pose error.

With e = (e_x [m], e_y [m], e_θ [rad]) the planned minus the actual object pose in the plan
frame (x along the push), the law asks the object for the twist u = k e + k_i ∫ e dt
(u_x, u_y [m/s], u_θ [rad/s]) and carries it to the pusher origin as a point of the object,
v = (u_x − u_θ r_y, u_y + u_θ r_x, u_θ), with r the pusher origin's lever from the object's
centre in the plan frame [m]: with both prongs sticking the object moves with the pusher.
The integral is frozen while any prong's measured normal force is below ``contact_force``
(50 mN): an object placed ahead of the plan is not touched yet, and integrating its error
would back the pusher away from it. The threshold sits above the noise of the proxy's force
estimate (σ = 20 mN at no load, docs/design.md §9): at 10 mN an unloaded prong read as
loaded on about a third of the steps, which restarted the contact seek's ramp and left the
seek at a tenth of its rate (docs/residual-and-feedback.md §4). With
``hold_off_contact`` (the default) the output is zero then too: on the ``reference`` path the
output is the offset's rate, so its P term is an integrator as well.

The lateral part of the output (plan-frame y, across the push) is capped at ``lateral_ratio``
times the plan's current speed: a pushed object is moved sideways only by the prongs'
friction, and the tuning pushes showed that a sideways correction faster than a few per
cent of the forward speed unloads a prong, which on the wedge starts a single-prong spin the
push never recovers from (docs/residual-and-feedback.md §4).

The turn is capped too: it may move the prong farthest from the object's centre at no more
than ``turn_ratio`` times the plan's speed. Uncapped, an angle error of a degree asked for
turns of 0.18-0.27 rad/s at a gain k = 11.3 /s, six to nine times the plan's own
turn rate on a 35° push; each lifted a prong for a step, and on the wedge one of them started a spin
(docs/residual-and-feedback.md §4).

The output passes through a first-order lag of ``smoothing`` (0.1 s). The law switches
between its modes (acting, holding, seeking) on the measured forces, so its raw output can
change sign from one 10 ms step to the next; on the MuJoCo plant, whose prong contact has a
time constant of two steps, that alternation rang the contact and lost it on 86-94 % of
steps (docs/residual-and-feedback.md §4).

While some prongs carry load and others do not (< ``contact_force``), the law instead turns
the plate about the loaded prongs' centre at ``seek_rate``, the way that brings the unloaded
prong farthest from them towards the face: with the output held there, a correction that
lifted a prong by a hundredth of a millimetre left the push on one prong for good
(docs/residual-and-feedback.md §4). The seek is fast (0.1 rad/s): at
0.01 rad/s a wedge that came off one prong as its turn began spun away from the plan
at about 17 mrad/s, faster than the plate followed, and 3 of 40 wedge trapezoid tuning
pushes failed; at 0.1 rad/s none of 240 tuning pushes did. It ramps up over
``seek_ramp`` (0.2 s) of one prong off: on MuJoCo, whose soft contact flickers below the
threshold for a step at a time, a seek at full rate from the first step lost contact on
15 % of the wedge's steps and failed 4 of 30 tuning pushes; ramped, 5 % and 1 (the slow
seek's 6 % and 1).

An optional slide guard (``slide_limit``, off by default) stops the sideways output where
it would slide the prongs along the face: with both prongs sticking, a sideways correction
carries the object with the plate, but on the wedge's slanted face the prongs sit on the
friction cone's edge, and a correction the object does not follow slides them instead. The
law reads where the prongs sit across the push, relative to the plan's spot, from the
observation (the offset plus the pose error carried to the pusher, :meth:`FeedbackLaw.slide`),
through a lag of ``slide_filter`` (1 s); once that has moved ``slide_limit`` from where it
was two lags after the prongs landed, the law no longer pushes sideways that way, and the
sideways error's integral stops growing. Unguarded, on sim tuning push 20412 (wedge, chirp)
the sideways integral held the output at its cap for 7 s while the object's sideways error
stayed at 0.1 mm; the prongs slid 0.9 mm along the face, one came off at its edge and the
wedge spun away (27 % angle error; PD-only 3.2 %). At 0.5 mm the guard keeps that push
(0.3 %), but on MuJoCo, whose soft contact creeps along the face, it blocks the sideways
corrections and costs 46-50 % of the law's translation error, so it is off
(docs/residual-and-feedback.md §4).

A catch-up phase (off unless the gains file sets ``catchup_time``) runs the push's first
seconds at higher gains with relaxed caps: 46 % of the steady law's mean error accrues in
the first 3 s, where the object's placement and mounting errors (1.4 mm, 0.55°) are caught up
at the caps' pace (about 0.3 mm/s). Its caps are relaxed only on steps where every prong
carries at least ``catchup_force``: unguarded, one wedge trapezoid tuning push of 50 came
off one prong and spun (63 % angle error). With ``gate_threshold`` set the law has its own
dead band, one during the catch-up (``catchup_gate``) and one after, in place of the
environment's (:mod:`pushctl.control.feedback_gains`).

The output is a residual twist like a policy's: it goes through the same residual path
(:mod:`pushctl.control.residual`). On the ``reference`` path it is the rate of the reference
offset, so the offset is k ∫ e + k_i ∬ e: integral and double-integral action on the pose.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from pushctl.control.feedback_gains import (
    DEFAULT_FEEDBACK_FILE,
    STEADY_FEEDBACK_FILE,
    FeedbackGains,
    load_feedback_gains,
)

__all__ = [
    "STEADY_FEEDBACK_FILE",
    "DEFAULT_FEEDBACK_FILE",
    "FeedbackGains",
    "FeedbackLaw",
    "load_feedback_gains",
]


class FeedbackLaw:
    """The PI law of one push (state: the error's integral). ``lever`` (2,) [m]: the pusher
    origin from the object's centre, plan frame; ``dt`` [s]: the time each call covers;
    ``prongs`` (k,) [m]: the prongs' offsets along the plate from its centre (the pusher
    frame's y, :meth:`PusherConfig.prong_offsets`; None: no contact seeking);
    ``gate_length`` [m]: the angle's weight in the law's own gate (``gains.gate_threshold``).

    The arithmetic runs on Python floats (:meth:`twist_floats`): the law runs at every 10 ms
    step under a policy, and numpy's per-call cost on 3-vectors was most of its time. Each
    component sees the same IEEE operations in the same order as the numpy form it replaced,
    so the same bits (tests/control/test_floats_bit_exact.py)."""

    def __init__(
        self,
        gains: FeedbackGains,
        lever: np.ndarray,
        dt: float,
        prongs: np.ndarray | None = None,
        gate_length: float = 0.05,
    ) -> None:
        self.gains = gains
        self.gate_length = float(gate_length)
        self.lever = np.asarray(lever, dtype=float).copy()
        self._lever = (float(self.lever[0]), float(self.lever[1]))
        self.dt = float(dt)
        self.prongs = None if prongs is None else np.asarray(prongs, dtype=float).copy()
        # the farthest prong's distance across the push from the object's centre [m]: a
        # turn u_θ moves it at |u_θ| · reach (fixed for the push; the turn cap's divisor)
        self._reach = None if prongs is None else float(np.max(np.abs(self.lever[1] + self.prongs)))
        self._integral = (0.0, 0.0, 0.0)
        self._output = (0.0, 0.0, 0.0)
        self.seeking_for = 0.0  # [s] since the law last saw every prong loaded or none
        # the slide guard's state: :meth:`slide` through its lag [m], started when every
        # prong first carried load; the time since then [s]; the landing spot it measures
        # from [m], taken two lags after that (None: not yet)
        self.slide_now: float | None = None
        self.since_landing = 0.0
        self.landed: float | None = None

    @property
    def integral(self) -> np.ndarray:
        """∫ e dt so far (3,) [m·s, m·s, rad·s] (a new array)."""
        return np.array(self._integral)

    @property
    def output(self) -> np.ndarray:
        """The lagged output of the last call (3,) [m/s, m/s, rad/s] (a new array)."""
        return np.array(self._output)

    def twist(
        self,
        error: np.ndarray,
        normal_forces: np.ndarray,
        speed: float | None = None,
        offset: np.ndarray | None = None,
        time: float | None = None,
    ) -> np.ndarray:
        """The pusher twist (3,) [m/s, m/s, rad/s], plan frame, for the pose ``error`` (3,)
        [m, m, rad] (planned minus actual) and the prongs' measured ``normal_forces`` (k,) [N];
        integrates the error unless a prong is below the contact threshold. ``speed`` [m/s]:
        the plan's object speed now, which caps the sideways rate (None: no cap). ``offset``
        (3,) [m, m, rad]: the pusher reference's offset built so far (the ``reference`` path),
        which the slide guard needs (None: no guard). ``time`` [s]: since the push began,
        which the catch-up phase needs (None: no catch-up). With ``smoothing`` τ > 0 the
        output follows the law through a first-order lag of τ."""
        return np.array(
            self.twist_floats(
                np.asarray(error, dtype=float).tolist(),
                np.asarray(normal_forces, dtype=float).tolist(),
                speed,
                None if offset is None else np.asarray(offset, dtype=float).tolist(),
                time,
            )
        )

    def twist_floats(
        self,
        error: Sequence[float],
        normal_forces: Sequence[float],
        speed: float | None = None,
        offset: Sequence[float] | None = None,
        time: float | None = None,
    ) -> tuple[float, float, float]:
        """:meth:`twist` on Python floats: ``error`` (e_x, e_y, e_θ), one normal force per
        prong, ``offset`` (x, y, yaw) or None; returns (v_x, v_y, ω). Inside the law's own
        gate the output is zero and the state (integral, lag, seek) stays as it was, as when
        the environment's gate is shut and the law is not called."""
        catching_up = time is not None and time < self.gains.catchup_time
        if self.gains.gate_threshold is not None:
            threshold = self.gains.catchup_gate if catching_up else self.gains.gate_threshold
            e_x, e_y, e_w = error
            if math.hypot(e_x, e_y, self.gate_length * e_w) <= threshold:
                return (0.0, 0.0, 0.0)
        raw = self._law(error, normal_forces, speed, offset, catching_up)
        tau = self.gains.smoothing
        if tau <= 0.0:
            return raw
        gain = self.dt / (tau + self.dt)
        o_x, o_y, o_w = self._output
        self._output = (
            o_x + gain * (raw[0] - o_x),
            o_y + gain * (raw[1] - o_y),
            o_w + gain * (raw[2] - o_w),
        )
        return self._output

    def slide(self, error: Sequence[float], offset: Sequence[float]) -> float:
        """Where the pusher sits across the push on the object, relative to the plan's spot
        [m], from the pose ``error`` (3,) and the reference ``offset`` (3,): the pusher is
        at the plan's pusher position plus the offset and the object at the plan's pose
        minus the error, so in the object's frame the pusher origin is the plan's lever plus
        offset + error + e_θ ẑ × lever (first order in e_θ); this is its y. Off the true spot
        by the PD's own tracking error (0.2 mm on push 20412), which changes slowly: the guard
        reads how this moves, not its value."""
        return float(offset[1] + error[1] + error[2] * self._lever[0])

    def _law(
        self,
        error: Sequence[float],
        normal_forces: Sequence[float],
        speed: float | None = None,
        offset: Sequence[float] | None = None,
        catching_up: bool = False,
    ) -> tuple[float, float, float]:
        """The law's twist before the lag (:meth:`twist_floats`); ``catching_up``: in the
        catch-up phase (its gains; its caps if every prong carries ``catchup_force``)."""
        gains = self.gains
        e_x, e_y, e_w = (float(value) for value in error)
        loaded = [force >= gains.contact_force for force in normal_forces]
        all_loaded = all(loaded)
        seeking = not all_loaded and any(loaded)  # some prongs carry load, not all
        self.seeking_for = self.seeking_for + self.dt if seeking else 0.0
        # how far the prongs have moved across the push since they landed [m] (0: no guard)
        slid = 0.0
        if offset is not None and math.isfinite(gains.slide_limit):
            now = self.slide((e_x, e_y, e_w), offset)
            if self.slide_now is None:
                if all_loaded:  # the lag starts where the prongs landed
                    self.slide_now = now
                    self.since_landing = 0.0
            else:
                tau = gains.slide_filter
                self.slide_now += (self.dt / (tau + self.dt)) * (now - self.slide_now)
                self.since_landing += self.dt
                if self.landed is None and self.since_landing >= 2.0 * tau:
                    self.landed = self.slide_now
            if self.landed is not None and self.slide_now is not None:  # landed: both set
                slid = self.slide_now - self.landed
        guarded = abs(slid) >= gains.slide_limit  # a push sideways the way they slid is barred
        if all_loaded:
            dt = self.dt
            step_y = dt * e_y
            if guarded and step_y * slid > 0.0:
                # an e_y of the sign they slid asks for more output that way: hold it there
                step_y = 0.0
            i_x, i_y, i_w = self._integral
            self._integral = (i_x + dt * e_x, i_y + step_y, i_w + dt * e_w)
        elif gains.hold_off_contact:
            if seeking and self.prongs is not None and gains.seek_rate > 0.0:
                return self._seek(np.array(loaded))
            return (0.0, 0.0, 0.0)
        k, k_i = gains.k, gains.k_i
        lateral_ratio, turn_ratio = gains.lateral_ratio, gains.turn_ratio
        if catching_up:
            k, k_i = gains.catchup_k, gains.catchup_k_i
            if min(normal_forces) >= gains.catchup_force:  # every prong carries load
                lateral_ratio = gains.catchup_lateral_ratio
                turn_ratio = gains.catchup_turn_ratio
        i_x, i_y, i_w = self._integral
        u_x, u_y, u_w = k * e_x + k_i * i_x, k * e_y + k_i * i_y, k * e_w + k_i * i_w
        r_x, r_y = self._lever
        if self._reach is not None and speed is not None and math.isfinite(turn_ratio):
            cap = turn_ratio * abs(speed) / self._reach
            u_w = min(max(u_w, -cap), cap)
        lateral = u_y + u_w * r_x
        if speed is not None and math.isfinite(lateral_ratio):
            cap = lateral_ratio * abs(speed)
            lateral = min(max(lateral, -cap), cap)
        if guarded and lateral * slid > 0.0:
            lateral = 0.0
        return (u_x - u_w * r_y, lateral, u_w)

    def _seek(self, loaded: np.ndarray) -> tuple[float, float, float]:
        """The plate's turn about the loaded prongs' centre (0, c) (pusher frame; x along the
        push, into the face) that moves the unloaded prong at offset f farthest from it
        forwards: ω ẑ × (0, f − c) has x-component −ω (f − c), so ω = −sign(f − c) · rate;
        the plate's origin then moves at ω ẑ × (0, −c) = (ω c, 0)."""
        prongs = self.prongs
        assert prongs is not None
        centre = float(np.mean(prongs[loaded]))
        free = prongs[~loaded]
        farthest = float(free[np.argmax(np.abs(free - centre))])
        ramp = self.gains.seek_ramp
        rate = self.gains.seek_rate * (min(1.0, self.seeking_for / ramp) if ramp > 0.0 else 1.0)
        omega = -math.copysign(rate, farthest - centre)
        return (omega * centre, 0.0, omega)
