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


class WriteError(PushctlError):
    """A file that could not be written (a full disk, a read-only directory, no permission).
    The message names the file the user asked for, never a temporary one; the file that was
    there before, if any, is left as it was."""


class DamagedFileError(ConfigError):
    """A checkpoint, policy or results file whose content does not match the digest it was
    written with, or that misses rows it names: damaged or edited after it was written."""


def reason(error: BaseException) -> str:
    """What ``error`` says, for a one-line message: a KeyError's missing key as the word
    ``no KEY`` (not the key's repr), anything else its message on one line (or its type)."""
    if isinstance(error, KeyError) and error.args:
        return f"no {error.args[0]}"
    text = " ".join(str(error).split())
    return text or type(error).__name__
