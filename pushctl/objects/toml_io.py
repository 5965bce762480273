"""Objects from and to TOML files.

Keys (SI units)::

    name = "box"                  # optional, default: the file's stem
    mass = 0.30                   # [kg]
    height = 0.088                # [m] top-surface height at the origin of these coordinates
    slope = [0.0, 0.0]            # optional [m/m] gradient of the top surface
    footprint = [[x, y], ...]     # [m] convex polygon, either orientation ...
    size = [0.088, 0.088]         # ... or a rectangle [length along x, width along y]
    pushed_face = 3               # optional edge index (vertex i -> i+1); default: faces -x
    pusher_mass = 0.030           # optional [kg]
    support_points = [[x, y], ...]  # optional [m]; default: the footprint's corners
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from pushctl.errors import ConfigError
from pushctl.files.toml import read_toml
from pushctl.objects.spec import DEFAULT_PUSHER_MASS, ObjectSpec, object_from_footprint

_KEYS = (
    "name",
    "mass",
    "height",
    "slope",
    "footprint",
    "size",
    "pushed_face",
    "pusher_mass",
    "support_points",
)


def load_object(path: str | Path) -> ObjectSpec:
    """Read an object file (keys in the module docstring).

    Raises:
        ConfigError: a missing, unreadable or corrupt file, an unknown or missing key, or
            invalid geometry or mass; the message names the file.
    """
    path = Path(path)
    table = read_toml(path, "object file")
    try:
        return _from_table(table, default_name=path.stem)
    except ConfigError as exc:
        raise ConfigError(f"{path}: {exc}") from None


def _from_table(table: dict[str, Any], default_name: str) -> ObjectSpec:
    unknown = sorted(set(table) - set(_KEYS))
    if unknown:
        raise ConfigError(f"unknown key(s) {', '.join(unknown)}; accepted: {', '.join(_KEYS)}")
    for key in ("mass", "height"):
        if key not in table:
            raise ConfigError(f"missing key '{key}' (a number in SI units)")
    name = table.get("name", default_name)
    if not isinstance(name, str) or not name:
        raise ConfigError(f"name must be a non-empty string, got {name!r}")
    mass = _number(table, "mass")
    height = _number(table, "height")
    return object_from_footprint(
        name,
        _footprint(table),
        mass,
        height,
        slope=table.get("slope", (0.0, 0.0)),
        pushed_face=table.get("pushed_face"),
        pusher_mass=_number(table, "pusher_mass", DEFAULT_PUSHER_MASS),
        support_points=table.get("support_points"),
    )


def _number(table: dict[str, Any], key: str, default: float | None = None) -> float:
    value = table.get(key, default)
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ConfigError(f"{key} must be a number, got {value!r}")
    return float(value)


def _footprint(table: dict[str, Any]) -> Any:
    """The footprint from ``footprint`` or from ``size = [length, width]``."""
    if ("footprint" in table) == ("size" in table):
        raise ConfigError("give exactly one of footprint = [[x, y], ...] or size = [length, width]")
    if "footprint" in table:
        return table["footprint"]
    size = table["size"]
    ok = isinstance(size, list) and len(size) == 2
    if not ok or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in size):
        raise ConfigError(f"size must be [length, width] in metres, got {size!r}")
    length, width = (float(v) for v in size)
    if not (length > 0.0 and width > 0.0):
        raise ConfigError(f"size must be positive [length, width] in metres, got {size!r}")
    half_l, half_w = 0.5 * length, 0.5 * width
    return [[-half_l, -half_w], [half_l, -half_w], [half_l, half_w], [-half_l, half_w]]


def object_to_toml(spec: ObjectSpec) -> str:
    """TOML text describing ``spec`` in its local frame; :func:`load_object` reads it back."""
    lines = [
        f"name = {_string(spec.name)}",
        f"mass = {spec.mass!r}",
        f"height = {spec.height_at_origin!r}",
        f"slope = {_array(spec.slope.tolist())}",
        f"footprint = {_array(spec.footprint.tolist())}",
        "pushed_face = 0",
        f"pusher_mass = {spec.pusher_mass!r}",
        f"support_points = {_array(spec.support_points.tolist())}",  # type: ignore[union-attr]
    ]
    return "\n".join(lines) + "\n"


def write_object(spec: ObjectSpec, path: str | Path) -> None:
    """Write ``spec`` to ``path`` as TOML (see :func:`object_to_toml`)."""
    Path(path).write_text(object_to_toml(spec), encoding="utf-8")


def _string(text: str) -> str:
    escaped = text.replace("\\", "\\\\").replace('"', '\\"')
    return f'"{escaped}"'


def _array(values: Any) -> str:
    if isinstance(values, list):
        return "[" + ", ".join(_array(v) for v in values) + "]"
    return repr(float(values))
