"""The controller's terms of an arm whose pusher is mounted other than the controller believes.

With a mounting error (docs/design.md §9) the world's arm carries the real plate and prongs,
while the controller's model (an :class:`~pushctl.arm.model.ArmModel` with the nominal
pusher, same mass) computes the pusher frame, its Jacobian and g(q) it servoes with. Running
that model's whole pass every step repeats what the world has just computed: both models
share every joint, so the joint placements and Jacobians of the world's pass are the
controller's too. :class:`BelievedTerms` takes the controller's quantities from the world's
own pass instead, bit for bit what the controller's model computes:

- the pusher frame and its Jacobian: the world's arm carries the nominal pusher frame as one
  more massless frame (the same placement on the same joint), computed in its pass
  (:meth:`~pushctl.arm.model.ArmModel.nominal_pusher`); with no mounting yaw (only the
  prongs displaced) the pusher frames coincide;
- g(q): computeAllTerms' g depends on the joint placements and each body's mass and centre
  of mass only. The plate's centre of mass lies on the tool axis, which the mounting yaw
  turns about, so the two models' masses and centres agree, to the bit in about two draws
  of three; then the world's g is the controller's. Otherwise (a last-bit difference of
  the centre, ~5e-20 m) the controller's model forms its own g by the same arithmetic
  (:meth:`~pushctl.arm.model.ArmModel.gravity_as_computed`, a third of a pass).
"""

from __future__ import annotations

import numpy as np

from pushctl.arm.model import ArmModel, ArmTerms
from pushctl.errors import ConfigError


def same_gravity_terms(a: ArmModel, b: ArmModel) -> bool:
    """Whether ``a`` and ``b`` compute the same g(q) to the bit: the same joints, gravity
    and, for every body, the same mass and centre of mass (bit for bit)."""
    if a.name != b.name or not np.array_equal(a.model.gravity.vector, b.model.gravity.vector):
        return False
    return all(
        x.mass == y.mass and np.array_equal(x.lever, y.lever)
        for x, y in zip(a.model.inertias, b.model.inertias, strict=True)
    )


class BelievedTerms:
    """The controller's :class:`ArmTerms` from the world arm's terms.

    ``world_arm``: the world's arm (the real pusher); ``controller_arm``: the controller's,
    the same arm with ``world_arm.pusher.nominal``. Calling it with the world's terms at
    joint state ``q`` (nq,) [rad] returns terms whose ``g``, ``pusher_position``,
    ``pusher_rotation`` and ``pusher_jacobian`` are the controller model's at ``q``, bit for
    bit; M, nle and the prong points stay the world's (no controller reads them).
    """

    def __init__(self, world_arm: ArmModel, controller_arm: ArmModel) -> None:
        if world_arm.name != controller_arm.name or controller_arm.pusher != (
            world_arm.pusher.nominal
        ):
            raise ConfigError(
                "the controller's arm must be the world's arm with the nominal pusher "
                f"({world_arm.name!r}, {world_arm.pusher.nominal!r}), got "
                f"{controller_arm.name!r} with {controller_arm.pusher!r}"
            )
        self.world_arm, self.controller_arm = world_arm, controller_arm
        self.same_gravity = same_gravity_terms(world_arm, controller_arm)

    def __call__(self, terms: ArmTerms, q: np.ndarray, v: np.ndarray) -> ArmTerms:
        if self.world_arm.nominal_pusher_frame_id is None:
            # no mounting yaw: the world's pusher frame is the nominal one
            if self.same_gravity:
                return terms
            return terms._replace(g=self.controller_arm.gravity_as_computed(q))
        frame = self.world_arm.nominal_pusher(terms)
        if frame is None:  # not from the world arm's last pass
            return self.controller_arm.compute(q, v)
        g = terms.g if self.same_gravity else self.controller_arm.gravity_as_computed(q)
        return ArmTerms(
            terms.M,
            terms.nle,
            g,
            terms.prong_positions,
            terms.prong_jacobians,
            frame.position,
            frame.rotation,
            frame.jacobian,
        )
