"""Rigid planar objects on the table: shapes, mass properties, support loads and geometry.

See docs/design.md §3 ("Objects", "Ground friction", "Pusher–object contacts").
"""

from pushctl.objects.geometry import (
    ConvexPolygon,
    polygon_world,
    pose_components,
    rotation,
    signed_distance,
    signed_distance_batch,
    to_local,
    to_world,
    vectors_to_local,
    vectors_to_world,
)
from pushctl.objects.mass import MassProperties, mass_properties, support_loads
from pushctl.objects.presets import (
    OBJECT_NAMES,
    make_object,
    resolve_object,
    with_masses,
    with_pressure_offset,
)
from pushctl.objects.spec import DEFAULT_PUSHER_MASS, ObjectSpec, object_from_footprint
from pushctl.objects.toml_io import load_object, object_to_toml, write_object

__all__ = [
    "DEFAULT_PUSHER_MASS",
    "OBJECT_NAMES",
    "ConvexPolygon",
    "MassProperties",
    "ObjectSpec",
    "load_object",
    "make_object",
    "mass_properties",
    "object_from_footprint",
    "object_to_toml",
    "polygon_world",
    "pose_components",
    "resolve_object",
    "rotation",
    "signed_distance",
    "signed_distance_batch",
    "support_loads",
    "to_local",
    "to_world",
    "vectors_to_local",
    "vectors_to_world",
    "with_masses",
    "with_pressure_offset",
    "write_object",
]
