"""The world's numerical and friction settings (:class:`WorldConfig`) and its default
object pose."""

from __future__ import annotations

import math
from dataclasses import dataclass

from pushctl.config import GRAVITY
from pushctl.errors import ConfigError

MAX_SLIP_ITERATIONS = 6
"""Re-solves of one step for its friction directions (``WorldConfig.slip_iterations``'s
default). If they have not settled by then, the step keeps its first solution (the boxes
aligned with the velocity before the step)."""

STICK_FRACTION = 1.0 - 1e-6
"""The stick rule's threshold as measured (``WorldConfig.stick_fraction``, off by default): a
moving sliding point whose along-row friction impulse is below this fraction of its bound is
not at its bound, so not sliding."""

FRICTION_MODELS = ("slip_box", "polygon", "axis_box")
"""Ground friction models of the world (``WorldConfig.friction_model``), per support point j
of load N_j, bound μ(p_j) N_j:

- ``slip_box`` (the default, what ``results/`` was made with): two rows along and across the
  point's slip direction, refined against the solved slip (docs/design.md §3); isotropic;
- ``polygon``: a regular polygon of ``facets`` sides, fixed to the table: facets/2 rows per
  point along the directions kπ/(facets/2), each bounded by ±π/facets of the full bound (the
  sum of facets/2 segments); its support lies within 0.95–1.03 of the bound (8 facets),
  0.987–1.006 (16 facets);
- ``axis_box``: two rows along the table's x and y axes, each with the full bound: a square,
  up to √2 times the bound along a diagonal.

The two fixed models solve each step once (no refinement) with a relative compliance of
:data:`GROUND_COMPLIANCE` on their ground rows."""

GROUND_COMPLIANCE = 1e-2
"""Relative diagonal term on the ground rows of the fixed friction models (``polygon``,
``axis_box``): their D has rank 3 whatever the number of rows, and the many tied rows sent
the pivoting to its slow path; with it a held point may creep at 1 % of the velocity its
friction impulse alone would give it, and sliding points are unchanged."""

DEFAULT_OBJECT_POSE = (0.42, 0.0, 0.0)
"""Object pose (x [m], y [m], θ [rad]) of ``World.reset()`` without arguments: 12 cm ahead
of the ready pusher of the Kinova arm, pushed face towards it."""


@dataclass(frozen=True)
class WorldConfig:
    """Numerical and friction parameters of the world step (SI units).

    ``dt`` [s] is the control and output step; ``substeps`` splits it internally.
    ``contact_margin`` [m]: prongs nearer than this to the footprint enter the MLCP (with a
    positive gap the row only acts if the step would close it: speculative contact).
    ``stabilisation`` (0, 1]: fraction of a penetration removed per (sub)step.
    ``gravity`` [m/s²]: magnitude, for the arm and the object's support loads.
    ``slip_iterations``: re-solves of a step whose ground friction directions move (see
    ``StepSolver.solve``); a step not settled after them keeps its first solution. 6, the
    default, is what ``results/`` was made with; fewer saves solves where objects slip, but
    under a tenth of a training push step's time.
    ``stick_fraction`` [0, 1): the stick rule
    (:func:`~pushctl.contact.compiled.assembly.refine_slip`):
    a sliding support point that moves and whose along-row friction impulse comes out
    below this fraction of its bound gets the rest box, and the step is solved again. 0,
    the default, turns it off and is what ``results/`` was made with; 1 − 10⁻⁶
    (:data:`STICK_FRACTION`) is the rule as measured, not yet validated enough to be the
    default.
    """

    dt: float = 0.01
    mu_ground: float = 0.3
    mu_contact: float = 0.4
    substeps: int = 1
    contact_margin: float = 0.01
    stabilisation: float = 0.3
    gravity: float = GRAVITY
    slip_iterations: int = MAX_SLIP_ITERATIONS
    stick_fraction: float = 0.0
    friction_model: str = "slip_box"
    facets: int = 8

    def __post_init__(self) -> None:
        if not (math.isfinite(self.dt) and self.dt > 0.0):
            raise ConfigError(f"dt must be a positive number of seconds, got {self.dt!r}")
        for name in ("mu_ground", "mu_contact"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0.0):
                raise ConfigError(f"{name} must be a finite number >= 0, got {value!r}")
        if not (isinstance(self.substeps, int) and self.substeps >= 1):
            raise ConfigError(f"substeps must be an integer >= 1, got {self.substeps!r}")
        iterations = self.slip_iterations
        if isinstance(iterations, bool) or not (isinstance(iterations, int) and iterations >= 0):
            raise ConfigError(f"slip_iterations must be an integer >= 0, got {iterations!r}")
        stick = self.stick_fraction
        if isinstance(stick, bool) or not (isinstance(stick, (int, float)) and 0 <= stick < 1):
            raise ConfigError(f"stick_fraction must be a number in [0, 1), got {stick!r}")
        object.__setattr__(self, "stick_fraction", float(stick))  # one compiled signature
        if self.friction_model not in FRICTION_MODELS:
            raise ConfigError(
                f"friction_model must be one of {', '.join(FRICTION_MODELS)}, "
                f"got {self.friction_model!r}"
            )
        facets = self.facets
        if isinstance(facets, bool) or not (
            isinstance(facets, int) and facets >= 8 and facets % 4 == 0
        ):
            raise ConfigError(f"facets must be a multiple of 4, >= 8, got {facets!r}")
        if not (math.isfinite(self.contact_margin) and self.contact_margin > 0.0):
            raise ConfigError(f"contact_margin must be > 0 m, got {self.contact_margin!r}")
        if not (0.0 < self.stabilisation <= 1.0):
            raise ConfigError(f"stabilisation must be in (0, 1], got {self.stabilisation!r}")
        if not (math.isfinite(self.gravity) and self.gravity >= 0.0):
            raise ConfigError(f"gravity must be a finite number >= 0 m/s², got {self.gravity!r}")
