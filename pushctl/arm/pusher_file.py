"""Pusher files: the plate and its k = 1–4 prongs as TOML (``experiments/pushers/*.toml``).

Keys (SI units, every one optional; an absent key keeps the paper's two-prong plate of
Table II, :class:`~pushctl.config.PusherConfig`)::

    n_prongs = 3           # k, 1 … 4
    prong_spacing = 0.020  # m between neighbouring prongs (centred on the plate)
    width = 0.104          # m, the plate along the pushed face
    height = 0.048         # m, vertical
    thickness = 0.030      # m, along the push
    mass = 0.030           # kg

The prongs must fit on the plate (k − 1 spacings ≤ width); whether they fit on an object's
pushed face the planner checks, naming both. The mounting error of the plant unknowns is
not a file key: it is drawn per scenario (``pushctl/defaults/randomisation.toml``).
"""

from __future__ import annotations

from dataclasses import fields
from pathlib import Path

from pushctl.config import PusherConfig
from pushctl.errors import ConfigError
from pushctl.files.toml import read_toml

KEYS = ("n_prongs", "prong_spacing", "width", "height", "thickness", "mass")
"""The keys of a pusher file."""


def load_pusher(path: str | Path) -> PusherConfig:
    """The pusher described by the TOML file ``path``.

    Raises:
        ConfigError: a missing, unreadable or corrupt file, an unknown key, a value of the
            wrong type, or geometry :class:`PusherConfig` rejects; one line naming the file.
    """
    path = Path(path)
    table = read_toml(path, "pusher file")
    try:
        return pusher_from_table(table)
    except ConfigError as exc:
        raise ConfigError(f"pusher file {path}: {exc}") from None


def pusher_from_table(table: dict) -> PusherConfig:
    """A :class:`PusherConfig` from the keys of :data:`KEYS` (absent ones: the defaults)."""
    unknown = sorted(str(key) for key in set(table) - set(KEYS))
    if unknown:
        raise ConfigError(f"unknown key(s) {', '.join(unknown)}; accepted: {', '.join(KEYS)}")
    values: dict[str, float | int] = {}
    for key, value in table.items():
        if key == "n_prongs":
            if isinstance(value, bool) or not isinstance(value, int):
                raise ConfigError(f"n_prongs must be an integer 1 … 4, got {value!r}")
            values[key] = value
        elif isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ConfigError(f"{key} must be a number in SI units, got {value!r}")
        else:
            values[key] = float(value)
    return PusherConfig(**values)  # type: ignore[arg-type]


def pusher_to_toml(pusher: PusherConfig) -> str:
    """TOML text :func:`load_pusher` reads back as ``pusher`` (its nominal part)."""
    defaults = {f.name for f in fields(PusherConfig)}
    assert set(KEYS) <= defaults
    return "".join(f"{key} = {getattr(pusher, key)!r}\n" for key in KEYS)


def resolve_pusher(path: str | Path | None) -> PusherConfig | None:
    """``--pusher``'s value: None (the paper's plate, the object's Table II pusher mass) or
    the pusher of a TOML file."""
    if path is None:
        return None
    if Path(path).suffix.lower() != ".toml":
        raise ConfigError(f"--pusher must be a .toml pusher file, got {str(path)!r}")
    return load_pusher(path)
