"""The objects of the paper's Table II, and name-or-file resolution.

Presets are built from their physical description (footprint, height field, mass) exactly as
in docs/design.md §3; everything else (CoM, inertia, support loads, face geometry) is computed.
"""

from __future__ import annotations

import dataclasses
from functools import cache
from pathlib import Path

import numpy as np

from pushctl.errors import ConfigError
from pushctl.objects.spec import ObjectSpec, object_from_footprint
from pushctl.objects.toml_io import load_object

OBJECT_NAMES = ("cube", "wedge")
"""Names accepted by :func:`make_object`."""

_CUBE_SIDE = 0.088  # [m], Table II
_WEDGE_LENGTH = 0.140  # [m] along the push direction
_WEDGE_WIDTH = 0.085  # [m] along the pushed (back) face
_WEDGE_HEIGHT = 0.080  # [m] at the back face, sloping to 0 at the front


def _rectangle(length: float, width: float) -> list[list[float]]:
    """Counter-clockwise rectangle with its −x edge on x = 0, (4, 2) [m]."""
    return [[0.0, 0.0], [length, 0.0], [length, width], [0.0, width]]


@cache
def _preset(name: str) -> ObjectSpec:
    if name == "cube":
        return object_from_footprint(
            "cube", _rectangle(_CUBE_SIDE, _CUBE_SIDE), 0.300, _CUBE_SIDE, pusher_mass=0.030
        )
    if name == "wedge":
        # Height H at the back face (x = 0, the pushed face) falling linearly to 0 at x = L.
        return object_from_footprint(
            "wedge",
            _rectangle(_WEDGE_LENGTH, _WEDGE_WIDTH),
            0.350,
            _WEDGE_HEIGHT,
            slope=(-_WEDGE_HEIGHT / _WEDGE_LENGTH, 0.0),
            pusher_mass=0.040,
        )
    raise _unknown(name)


def _unknown(name: object) -> ConfigError:
    return ConfigError(
        f"unknown object {name!r}: choose one of {', '.join(OBJECT_NAMES)}, "
        "or give a path to a .toml object file"
    )


def make_object(
    name: str, *, mass: float | None = None, pusher_mass: float | None = None
) -> ObjectSpec:
    """A preset object of Table II, optionally with another object or pusher mass [kg].

    The overrides change only the masses: geometry stays, and the inertia and support loads
    follow the new mass (uniform density).
    """
    if name not in OBJECT_NAMES:
        raise _unknown(name)
    return with_masses(_preset(name), mass=mass, pusher_mass=pusher_mass)


def with_masses(
    spec: ObjectSpec, *, mass: float | None = None, pusher_mass: float | None = None
) -> ObjectSpec:
    """``spec`` with another object and/or pusher mass [kg] (None keeps the current one)."""
    if mass is None and pusher_mass is None:
        return spec
    return dataclasses.replace(
        spec,
        mass=spec.mass if mass is None else mass,
        pusher_mass=spec.pusher_mass if pusher_mass is None else pusher_mass,
    )


def with_pressure_offset(spec: ObjectSpec, offset) -> ObjectSpec:
    """``spec`` with its support loads balanced about ``offset`` (2,) [m] (object frame,
    from the CoM) instead of the CoM: a shifted centre of pressure, same total load."""
    return dataclasses.replace(spec, pressure_offset=np.asarray(offset, dtype=float))


def resolve_object(
    name_or_path: str | Path, *, mass: float | None = None, pusher_mass: float | None = None
) -> ObjectSpec:
    """A preset by name (see :data:`OBJECT_NAMES`) or an object from a .toml file.

    ``mass`` and ``pusher_mass`` [kg] override the preset's or the file's values, as in
    :func:`make_object`.
    """
    if isinstance(name_or_path, str) and name_or_path in OBJECT_NAMES:
        return make_object(name_or_path, mass=mass, pusher_mass=pusher_mass)
    path = Path(name_or_path)
    if path.suffix.lower() == ".toml" or path.exists():
        return with_masses(load_object(path), mass=mass, pusher_mass=pusher_mass)
    raise _unknown(str(name_or_path))
