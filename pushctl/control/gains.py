"""Gains of the PD baseline (docs/design.md §5) and their TOML file (shipped:
``pushctl/defaults/pd_gains.toml``).

The file is written by ``pushctl tune-pd`` and read by every command that runs the PD
controller. Keys, all under ``[pd]``::

    kp = 200.0            # joint stiffness K_p [N·m/rad]
    kv = 20.0             # joint damping K_v [N·m·s/rad]
    kx_linear = 10.0      # operational-space position gain [1/s]
    kx_angular = 10.0     # operational-space orientation gain [1/s]
    ik_damping = 1e-3     # λ of the damped pseudo-inverse Jᵀ(J Jᵀ + λ² I)⁻¹ [-]
    posture_gain = 1.0    # null-space pull towards the ready configuration [1/s]

Other tables in the file (the record of the search that produced it) are kept for the
reader and ignored here.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields
from pathlib import Path

from pushctl.defaults import default_file
from pushctl.errors import ConfigError
from pushctl.files.toml import check_keys, read_toml
from pushctl.ranges import check_range

DEFAULT_GAINS_FILE = default_file("pd_gains.toml")
"""The tuned gains shipped with pushctl (package data, :mod:`pushctl.defaults`)."""


@dataclass(frozen=True)
class PDGains:
    """Gains of the joint PD baseline with operational-space IK (docs/design.md §5, eq. 14–15).

    ``kp`` [N·m/rad] and ``kv`` [N·m·s/rad]: the joint gains of eq. 15, the same on every
    joint. ``kx_linear`` and ``kx_angular`` [1/s]: feedback of the pusher frame's position
    and orientation error onto its commanded twist. ``ik_damping`` [-]: λ of the damped
    pseudo-inverse (mixed m/rad units, as J). ``posture_gain`` [1/s]: the ready
    configuration pulls the arm's one redundant direction (the elbow) back at this rate,
    inside the task's null space, so a long push does not let it wander.
    """

    kp: float = 200.0
    kv: float = 20.0
    kx_linear: float = 10.0
    kx_angular: float = 10.0
    ik_damping: float = 1e-3
    posture_gain: float = 1.0

    def __post_init__(self) -> None:
        for item in fields(self):
            value = getattr(self, item.name)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise ConfigError(f"PD gain {item.name} must be a number, got {value!r}")
            if not (math.isfinite(value) and value >= 0.0):
                raise ConfigError(f"PD gain {item.name} must be finite and >= 0, got {value!r}")
            object.__setattr__(self, item.name, float(value))
        if self.kv <= 0.0:
            raise ConfigError(f"PD gain kv must be > 0 N·m·s/rad, got {self.kv!r}")
        for item in fields(self):
            check_range(f"PD gain {item.name}", getattr(self, item.name))

    def as_dict(self) -> dict[str, float]:
        return asdict(self)


def load_gains(path: str | Path | None = None) -> PDGains:
    """The ``[pd]`` table of a gains file (default: the shipped :data:`DEFAULT_GAINS_FILE`).

    Raises ConfigError for a missing, unreadable or corrupt file, an unknown or missing
    key, or a bad value; the message names the file.
    """
    path = Path(path) if path is not None else DEFAULT_GAINS_FILE
    table = read_toml(path, "gains file")
    pd_table = table.get("pd")
    names = [item.name for item in fields(PDGains)]
    if not isinstance(pd_table, dict):
        raise ConfigError(f"gains file {path} has no [pd] table with keys {', '.join(names)}")
    check_keys(pd_table, names, f"gains file {path}: [pd]")
    try:
        return PDGains(**pd_table)
    except ConfigError as exc:
        raise ConfigError(f"gains file {path}: {exc}") from None


def gains_toml(gains: PDGains, header: str, search: dict[str, object] | None = None) -> str:
    """The text of a gains file: ``header`` comment lines, ``[pd]``, then an optional
    ``[search]`` table recording how the gains were found (numbers, strings, lists)."""
    lines = [f"# {line}" if not line.startswith("#") else line for line in header.splitlines()]
    lines += ["", "[pd]"]
    lines += [f"{name} = {value!r}" for name, value in gains.as_dict().items()]
    if search:
        lines += ["", "[search]"]
        lines += [f"{name} = {_toml_value(value)}" for name, value in search.items()]
    return "\n".join(lines) + "\n"


def _toml_value(value: object) -> str:
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_value(item) for item in value) + "]"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value)
    return str(value)
