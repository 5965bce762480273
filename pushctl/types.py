"""Value types shared across the package: what a world step returns and reports."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class StepResult:
    """The world after one step. Forces are averaged over the step's substeps.

    ``object_pose`` (3,) (x, y, θ) and ``object_velocity`` (3,) (vx, vy, ω), world frame.
    ``contact_forces`` (k, 2): normal and tangential force [N] of each prong on the object in
    the contact frame (e_n into the object, e_t = e_z × e_n); zero for a prong out of contact.
    ``prong_gaps`` (k,): signed distance [m] of each prong to the footprint (negative:
    penetration). ``arm_q`` (nq,), ``arm_v`` (nv,). ``mlcp_residual``: the largest
    natural-map residual of the step's solves; ``mlcp_iterations`` their sum.

    A world's results share its state arrays (each step gives the world arrays no one else
    holds and never writes into one a caller holds: :mod:`pushctl.contact.recycle`): read
    them, copy before writing. A caller that keeps only a raw pointer to an array's data
    (``ctypes``, ``__array_interface__``) and not the array must copy it.
    """

    object_pose: np.ndarray
    object_velocity: np.ndarray
    contact_forces: np.ndarray
    prong_gaps: np.ndarray
    arm_q: np.ndarray
    arm_v: np.ndarray
    mlcp_residual: float
    mlcp_converged: bool
    mlcp_iterations: int

    @classmethod
    def sharing(
        cls,
        object_pose: np.ndarray,
        object_velocity: np.ndarray,
        contact_forces: np.ndarray,
        prong_gaps: np.ndarray,
        arm_q: np.ndarray,
        arm_v: np.ndarray,
        mlcp_residual: float,
        mlcp_converged: bool,
        mlcp_iterations: int,
    ) -> StepResult:
        """The same as ``StepResult(...)`` with these fields, built in one step: the frozen
        dataclass's ``__init__`` sets each field through ``object.__setattr__``, on every
        world step. The arrays are taken as they are."""
        result = _new(cls)
        _set(result, "__dict__", {
            "object_pose": object_pose, "object_velocity": object_velocity,
            "contact_forces": contact_forces, "prong_gaps": prong_gaps, "arm_q": arm_q,
            "arm_v": arm_v, "mlcp_residual": mlcp_residual, "mlcp_converged": mlcp_converged,
            "mlcp_iterations": mlcp_iterations,
        })  # fmt: skip
        return result


_new, _set = object.__new__, object.__setattr__


@dataclass
class WorldStats:
    """Counters over the life of a world: steps, MLCP solves, fallbacks (solves that did not
    converge), warm-start hits, energy corrections (see ``World._advance_arm``), slip
    iterations (re-solves for the ground friction's direction, see ``World._substep``)."""

    steps: int = 0
    solves: int = 0
    fallbacks: int = 0
    warm_starts: int = 0
    energy_corrections: int = 0
    slip_iterations: int = 0  # re-solves to align ground friction with the slip
    slip_unsettled: int = 0  # steps whose friction directions did not settle (first solution kept)
    energy_removed: float = 0.0  # [J] spurious arm kinetic energy removed by the ledger
    max_residual: float = 0.0


@dataclass(frozen=True)
class ContactProblem:
    """One step's box-friction MLCP in impulses p = h λ, and what is needed to apply it.

    ``D (m, m) = A M̃⁻¹ Aᵀ``, ``b (m,)``, bounds and friction indices as in
    :func:`solve_box_mlcp`. Rows: per prong in contact (normal, tangential), then two
    ground-friction rows per support point. ``prongs``: the prongs those rows belong to.
    """

    h: float
    D: np.ndarray
    b: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    findex: np.ndarray
    mu: np.ndarray
    prongs: tuple[int, ...]
    A_arm: np.ndarray  # (2p, nv): the arm part of the prong rows (ground rows have none)
    v_arm_free: np.ndarray  # (nv,) [rad/s]
    Minv_At_arm: np.ndarray  # (nv, 2p)
    Minv_At_obj: np.ndarray  # (3, m)


@dataclass(frozen=True)
class PlanarPose:
    """A planar pose in the world frame: position ``x``, ``y`` [m], heading ``theta`` [rad]
    (counter-clockwise about +z; at 0 the object's pushed face faces the arm)."""

    x: float
    y: float
    theta: float

    def as_array(self) -> np.ndarray:
        """(3,) array (x, y, θ)."""
        return np.array([self.x, self.y, self.theta])

    @classmethod
    def from_array(cls, values) -> PlanarPose:
        """From any 3-sequence (x [m], y [m], θ [rad])."""
        x, y, theta = (float(v) for v in values)
        return cls(x, y, theta)

    @classmethod
    def from_degrees(cls, x: float, y: float, theta_deg: float) -> PlanarPose:
        """From x, y [m] and θ in degrees (the CLI's unit)."""
        return cls(float(x), float(y), float(np.deg2rad(theta_deg)))
