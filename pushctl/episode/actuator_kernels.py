"""The proxy's joint-friction arithmetic around a world step, compiled (numba): the prediction
q̂ of the new joint velocity and the joint impulse the step added besides the actuators
(:class:`~pushctl.episode.proxy.ProxyActuators` says what they are and why).

As numpy calls on 7-vectors and a 7 × 7 solve, a proxy step spent more time in the calls than
in the arithmetic itself (docs/performance.md). The algebra is
:mod:`pushctl.contact.compiled.algebra`'s loops, as in the world's step: one summation order on
every machine, where numpy's OpenBLAS and LAPACK pick their kernels by CPU.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from pushctl.contact.compiled.algebra import matvec, plus_diagonal, spd_solve


@njit(cache=True)
def secant_damping(viscous, coulomb, v, friction_velocity):
    """The friction's damping b + F_c / max(|q̇|, v_s) (nv,) [N·m·s/rad], a secant of the
    Coulomb + viscous law at joint velocities ``v`` (nv,) [rad/s]: ``−secant_damping(…) · v``
    is the law's torque."""
    out = np.empty(v.size)
    for i in range(v.size):
        out[i] = viscous[i] + coulomb[i] / max(abs(v[i]), friction_velocity)
    return out


@njit(cache=True)
def predict_friction(M, v, tau, nle, base, viscous, coulomb, friction_velocity, h, impulse):
    """The friction damping for the step from joint velocity ``v`` (nv,) [rad/s].

    ``M`` (nv, nv) the mass matrix, ``tau`` (nv,) [N·m] the applied explicit torque, ``nle``
    (nv,) [N·m] c + g, ``base`` (nv,) [N·m·s/rad] the world's own implicit damping, ``viscous``
    and ``coulomb`` (nv,) the friction law, ``h`` [s] the step, ``impulse`` (nv,) [N·m·s] the
    joint impulse r the contacts added in the previous step. Solves
    (M + h diag(base + d(v))) q̂ = M v + h (τ − nle) + r with d the secant damping, and
    returns the momentum M v + h (τ − nle) (nv,) [N·m·s] and d(q̂) (nv,) [N·m·s/rad].
    """
    nv = v.size
    momentum = matvec(M, v)
    for i in range(nv):
        momentum[i] += h * (tau[i] - nle[i])
    first = secant_damping(viscous, coulomb, v, friction_velocity)
    for i in range(nv):
        first[i] += base[i]
    rhs = np.empty((nv, 1))
    for i in range(nv):
        rhs[i, 0] = momentum[i] + impulse[i]
    predicted = spd_solve(plus_diagonal(M, h, first), rhs)[:, 0]
    return momentum, secant_damping(viscous, coulomb, predicted, friction_velocity)


@njit(cache=True)
def other_impulse(M, h, damping, v_new, momentum):
    """r = (M + h diag(damping)) q̇⁺ − momentum (nv,) [N·m·s]: what the step added to the
    joints' momentum besides the explicit torque and the implicit ``damping`` (nv,)
    [N·m·s/rad], given the new velocity ``v_new`` (nv,) [rad/s]."""
    out = matvec(plus_diagonal(M, h, damping), v_new)
    for i in range(out.size):
        out[i] -= momentum[i]
    return out
