"""The randomisation ranges of a ranges file (docs/design.md §7, §9; shipped:
``pushctl/defaults/randomisation.toml``).

Tables ``[sim]`` and ``[proxy]`` hold :class:`~pushctl.episode.scenario.ParameterRanges`
(``mu_ground``, ``mu_contact``, ``object_mass_scale``, ``pusher_mass_scale``, each
``[lo, hi]``); ``[targets]`` holds :class:`~pushctl.episode.scenario.TargetRanges`
(``forward`` [m], ``rotation_deg`` [deg], ``lateral`` [m]). Optional tables
``[unknowns.sim]`` and ``[unknowns.proxy]`` hold each plant's
:class:`~pushctl.episode.unknowns.UnknownRanges` (docs/design.md §9's plant unknowns); a file
without them has none (every half-width 0).
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from pathlib import Path

from pushctl.config import PLANT_KINDS
from pushctl.defaults import default_file
from pushctl.episode.scenario import ParameterRanges, TargetRanges
from pushctl.episode.unknowns import UnknownRanges
from pushctl.errors import ConfigError
from pushctl.files.toml import check_keys, read_toml

DEFAULT_RANGES_FILE = default_file("randomisation.toml")
"""The shipped ranges (package data, :mod:`pushctl.defaults`)."""

PLANTS = PLANT_KINDS
"""The plant kinds (:data:`pushctl.config.PLANT_KINDS`)."""

DEFAULT_PLANTS = ("sim", "proxy")
"""The plants an evaluation runs by default (``--plant both``)."""

_RANGES_OF = {"mujoco": "sim"}
"""Plants that draw their parameters from another plant's ranges."""


def plant_engine(plant: str | None) -> str:
    """The physics engine of ``plant`` (see :func:`pushctl.make_world`): ``mujoco`` for the
    MuJoCo plant, ``ours`` for every other."""
    return "mujoco" if plant == "mujoco" else "ours"


@dataclass(frozen=True)
class Randomisation:
    """Parameter ranges per plant, the goal ranges, and the plant unknowns' ranges per plant."""

    sim: ParameterRanges
    proxy: ParameterRanges
    targets: TargetRanges
    sim_unknowns: UnknownRanges = UnknownRanges()
    proxy_unknowns: UnknownRanges = UnknownRanges()

    def plant(self, name: str) -> ParameterRanges:
        """The ranges of plant ``name`` (one of :data:`PLANTS`)."""
        if name not in PLANTS:
            raise ConfigError(f"unknown plant {name!r}; accepted: {', '.join(PLANTS)}")
        ranges: ParameterRanges = getattr(self, _RANGES_OF.get(name, name))
        return ranges

    def unknowns(self, name: str) -> UnknownRanges:
        """The plant unknowns' ranges of plant ``name`` (one of :data:`PLANTS`; ``mujoco``
        draws the sim plant's, as it does for the parameters)."""
        self.plant(name)  # the same check
        ranges: UnknownRanges = getattr(self, f"{_RANGES_OF.get(name, name)}_unknowns")
        return ranges


def load_ranges(path: str | Path | None = None) -> Randomisation:
    """Read a ranges file (default: the shipped :data:`DEFAULT_RANGES_FILE`); ConfigError naming
    the file for a missing, unreadable or corrupt file, a missing table or a bad range."""
    path = Path(path) if path is not None else DEFAULT_RANGES_FILE
    table = read_toml(path, "ranges file")
    try:
        return Randomisation(
            sim=_table(table, "sim", ParameterRanges),
            proxy=_table(table, "proxy", ParameterRanges),
            targets=_table(table, "targets", TargetRanges),
            **_unknowns(table),
        )
    except ConfigError as exc:
        raise ConfigError(f"ranges file {path}: {exc}") from None


def _table(table: dict, name: str, kind):
    names = [item.name for item in fields(kind)]
    values = table.get(name)
    if not isinstance(values, dict):
        raise ConfigError(f"no [{name}] table with keys {', '.join(names)}")
    check_keys(values, names, f"[{name}]")
    return kind(**{key: _pair(value) for key, value in values.items()})


def _unknowns(table: dict) -> dict[str, UnknownRanges]:
    """The optional ``[unknowns.<plant>]`` tables as Randomisation's keyword arguments."""
    unknowns = table.get("unknowns", {})
    if not isinstance(unknowns, dict):
        raise ConfigError("unknowns must be a table of [unknowns.sim] and [unknowns.proxy]")
    check_keys(unknowns, list(PLANTS), "[unknowns]", all_required=False)
    names = [item.name for item in fields(UnknownRanges)]
    result = {}
    for plant, values in unknowns.items():
        if not isinstance(values, dict):
            raise ConfigError(f"[unknowns.{plant}] must be a table with keys {', '.join(names)}")
        check_keys(values, names, f"[unknowns.{plant}]", all_required=False)
        result[f"{plant}_unknowns"] = UnknownRanges(**values)
    return result


def _pair(value):
    """A TOML array as a tuple; anything else as is, for the range check to reject."""
    return tuple(value) if isinstance(value, list) else value
