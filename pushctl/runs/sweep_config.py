"""A sweep's TOML file: the base preset, the seeds, and the preset keys to vary.

```toml
preset = "quick"            # quick, paper, or a preset .toml (a relative path: from this file)
episodes = 60               # optional: episodes per run (default: the preset's)
seeds = "0-1"               # or [0, 1]
search = "grid"             # grid: every combination; random: `samples` draws
samples = 8                 # random only
search_seed = 0             # random only: the seed of the draws

[parameters]
"env.gate_threshold" = [0.0, 1.5e-4]                    # a list: these values
"ddpg.actor_lr" = { low = 1e-5, high = 1e-3, log = true }  # random only: a range
```

A key is ``section.field`` of the preset (``train``, ``env``, ``ddpg``; see
:mod:`pushctl.rl.presets`). A range with integer ends draws integers (ends included); with
``log = true`` it draws uniformly in the logarithm. Every configuration is checked against
the preset's own validation before anything runs.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from pushctl.errors import ConfigError
from pushctl.files.toml import check_keys, read_toml
from pushctl.rl.presets import PRESET_NAMES, Preset, load_preset
from pushctl.runs.seeds import parse_seeds

SEARCHES = ("grid", "random")
SECTIONS = ("train", "env", "ddpg")
TOP_KEYS = ("preset", "episodes", "seeds", "search", "samples", "search_seed", "parameters")
MAX_TRIALS = 10_000


@dataclass(frozen=True)
class Range:
    """A random-search range [low, high]; integers if both ends are, log-uniform if ``log``."""

    low: float
    high: float
    log: bool = False

    def draw(self, rng: np.random.Generator) -> float | int:
        integer = isinstance(self.low, int) and isinstance(self.high, int)
        if self.log:
            value = math.exp(rng.uniform(math.log(self.low), math.log(self.high)))
            return round(value) if integer else value
        if integer:
            return int(rng.integers(int(self.low), int(self.high) + 1))
        return float(rng.uniform(self.low, self.high))


@dataclass(frozen=True)
class Sweep:
    """A parsed sweep file: base ``preset``, ``episodes`` per run (None: the preset's),
    ``seeds``, ``search``, ``samples`` and ``search_seed`` (random), and ``parameters``:
    key → list of values or :class:`Range`, in the file's order."""

    preset: Preset
    episodes: int | None
    seeds: tuple[int, ...]
    search: str
    samples: int
    search_seed: int
    parameters: dict[str, list[Any] | Range]

    @property
    def keys(self) -> list[str]:
        return list(self.parameters)

    def configurations(self) -> list[dict[str, Any]]:
        """The configurations to train (key → value), each with every seed: the grid's
        combinations in order (the last key varying fastest), or ``samples`` draws."""
        if self.search == "grid":
            lists = [list(self.parameters[key]) for key in self.keys]  # type: ignore[arg-type]
            return [dict(zip(self.keys, combo, strict=True)) for combo in itertools.product(*lists)]
        rng = np.random.default_rng(self.search_seed)
        return [
            {
                key: spec.draw(rng) if isinstance(spec, Range) else spec[rng.integers(len(spec))]
                for key, spec in self.parameters.items()
            }
            for _ in range(self.samples)
        ]

    def preset_for(self, configuration: dict[str, Any]) -> Preset:
        """The base preset with ``configuration``'s values; its name lists them (a resumed
        sweep refuses a run directory trained with other values)."""
        return apply(self.preset, configuration)


def apply(preset: Preset, configuration: dict[str, Any]) -> Preset:
    """``preset`` with each ``section.field`` of ``configuration`` set; ConfigError (one
    line, naming the key) for an unknown key or a value the preset refuses."""
    values = preset.to_dict()
    for key, value in configuration.items():
        section, _, field = key.partition(".")
        if section not in SECTIONS or field not in values[section]:
            accepted = values.get(section, {}) if section in SECTIONS else {}
            raise ConfigError(
                f"sweep parameter {key!r} is not a preset key; accepted: "
                + (", ".join(f"{section}.{f}" for f in accepted) or "train.*, env.*, ddpg.*")
            )
        values[section][field] = value
    label = ",".join(f"{key}={value}" for key, value in configuration.items())
    values["name"] = f"{preset.name}[{label}]"
    try:
        return Preset.from_dict(values)
    except (ConfigError, TypeError, ValueError) as exc:
        raise ConfigError(f"sweep configuration {label}: {exc}") from None


def read_sweep(path: Path) -> Sweep:
    """Read and check a sweep file; ConfigError (one line, naming the file) if it is
    missing, not TOML, or anything in it is unknown or out of range. Every configuration is
    applied to the preset once, so a bad value stops the sweep before it starts."""
    path = Path(path)
    table = read_toml(path, "sweep file")
    try:
        sweep = _sweep(path, table)
        configurations = sweep.configurations()
        if len(configurations) * len(sweep.seeds) > MAX_TRIALS:
            raise ConfigError(f"at most {MAX_TRIALS} runs, got {len(configurations)} × seeds")
        for configuration in configurations:
            sweep.preset_for(configuration)
    except ConfigError as exc:
        raise ConfigError(f"sweep file {path}: {exc}") from None
    return sweep


def _sweep(path: Path, table: dict[str, Any]) -> Sweep:
    check_keys(table, list(TOP_KEYS), "the sweep", all_required=False)
    for key in ("preset", "seeds", "parameters"):
        if key not in table:
            raise ConfigError(f"{key!r} is missing")
    name = table["preset"]
    if not isinstance(name, str):
        raise ConfigError(f"preset must be a name or a .toml path, got {name!r}")
    if name not in PRESET_NAMES and not Path(name).is_absolute():
        name = str(path.parent / name)
    search = table.get("search", "grid")
    if search not in SEARCHES:
        raise ConfigError(f"unknown search {search!r}; accepted: {', '.join(SEARCHES)}")
    seeds = table["seeds"]
    seed_text = ",".join(str(s) for s in seeds) if isinstance(seeds, list) else str(seeds)
    parameters = _parameters(table["parameters"], search)
    episodes, samples, search_seed = (
        _integer(table, "episodes", None, 1),
        _integer(table, "samples", 8, 1),
        _integer(table, "search_seed", 0, 0),
    )
    return Sweep(
        load_preset(name),
        episodes,
        parse_seeds(seed_text),
        search,
        samples if samples is not None else 8,
        search_seed if search_seed is not None else 0,
        parameters,
    )


def _integer(table: dict[str, Any], key: str, default: int | None, low: int) -> int | None:
    value = table.get(key, default)
    if value is not None and (not isinstance(value, int) or isinstance(value, bool) or value < low):
        raise ConfigError(f"{key} must be an integer >= {low}, got {value!r}")
    return value


def _parameters(table: Any, search: str) -> dict[str, list[Any] | Range]:
    """Flatten ``[parameters]`` (quoted ``"env.x"`` keys or dotted ``env.x`` ones)."""
    if not isinstance(table, dict) or not table:
        raise ConfigError("[parameters] must be a table of at least one preset key")
    flat: dict[str, Any] = {}
    for key, value in table.items():
        if key in SECTIONS and isinstance(value, dict):
            flat.update({f"{key}.{field}": spec for field, spec in value.items()})
        else:
            flat[key] = value
    return {key: _spec(key, value, search) for key, value in flat.items()}


def _spec(key: str, value: Any, search: str) -> list[Any] | Range:
    if isinstance(value, list):
        if not value:
            raise ConfigError(f"parameter {key!r} lists no values")
        return value
    if isinstance(value, dict) and search == "random":
        check_keys(value, ["low", "high", "log"], f"parameter {key!r}", all_required=False)
        low: Any = value.get("low")
        high: Any = value.get("high")
        log = value.get("log", False)
        if not (_number(low) and _number(high)) or not isinstance(log, bool):
            raise ConfigError(f"parameter {key!r} needs numbers low < high, got {value}")
        if not low < high or (log and low <= 0):
            raise ConfigError(
                f"parameter {key!r} needs numbers low < high (> 0 with log = true), got {value}"
            )
        return Range(low, high, log)
    accepted = "a list of values" + (" or {low, high, log}" if search == "random" else "")
    raise ConfigError(f"parameter {key!r} must be {accepted} for a {search} search, got {value!r}")


def _number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)
