"""Typed errors of the core. Every one is a ``ValueError`` so callers can catch them broadly.

The message of each says what is wrong and what would be accepted, in one line; the CLI
prints it as is and exits with code 2.
"""


class PushctlError(ValueError):
    """Base class: bad input or an impossible request, described in one line."""


class ConfigError(PushctlError):
    """A name, size, mass, friction coefficient, time step or file that cannot be used."""


class StateError(PushctlError):
    """A state or command vector of the wrong length, or holding NaN or infinity."""


class MLCPInputError(PushctlError):
    """An MLCP whose arrays do not fit together (sizes, bounds, friction indices)."""


class PlanError(PushctlError):
    """A plan that cannot be executed: the goal is out of the arm's reach or the prongs
    cannot produce the wrench the plan needs. The message names the step and the reason."""
