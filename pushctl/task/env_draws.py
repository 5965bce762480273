"""What a reset of the push environment pushes: the object, profile and scenario drawn from
the environment's generator, or fixed by ``reset(options=…)``, planned with the nominal
parameters."""

from __future__ import annotations

from functools import cache
from typing import Any

import numpy as np

from pushctl.defaults import default_file
from pushctl.episode.draw import draw_planned_scenario
from pushctl.episode.ranges import Randomisation, load_ranges
from pushctl.episode.scenario import Scenario
from pushctl.errors import ConfigError
from pushctl.planning import Plan
from pushctl.task.env_config import EnvConfig

RESET_OPTIONS = ("object", "profile", "scenario_seed", "scenario")
"""Keys of ``reset(options=…)`` that fix a draw: the object, the profile, and the integer seed
of the scenario in the environment's stream (:func:`~pushctl.episode.draw.draw_scenario`);
or ``scenario``, a :class:`~pushctl.episode.scenario.Scenario` to push as it is (planned at
the reset; ``pushctl simulate``'s)."""


def default_draws(config: EnvConfig, rng: np.random.Generator) -> tuple[str, str, int]:
    """The object, profile and scenario seed a reset without options pushes. Every reset
    draws all three, so a fixed object does not shift the other draws."""
    drawn_object = config.objects[int(rng.integers(len(config.objects)))]
    drawn_profile = config.profiles[int(rng.integers(len(config.profiles)))]
    return drawn_object, drawn_profile, int(rng.integers(2**31 - 1))


def draw_reset(
    config: EnvConfig, rng: np.random.Generator, options: dict[str, Any]
) -> tuple[Scenario, int, Plan | None]:
    """The scenario of a reset with ``options`` (:data:`RESET_OPTIONS`), the goals redrawn,
    and its plan (None for a given ``scenario``: the episode plans it)."""
    unknown = sorted(set(options) - set(RESET_OPTIONS))
    if unknown:
        raise ConfigError(
            f"unknown reset option {unknown[0]!r}; accepted: {', '.join(RESET_OPTIONS)}"
        )
    drawn_object, drawn_profile, drawn_seed = default_draws(config, rng)
    if "scenario" in options:
        return options["scenario"], 0, None
    return draw_planned_scenario(
        int(options.get("scenario_seed", drawn_seed)),
        config.stream,
        options.get("object", drawn_object),
        options.get("profile", drawn_profile),
        plant=config.plant,
        ranges=shipped_ranges(config.ranges),
        duration=config.duration,
        dt=config.dt,
    )


@cache
def shipped_ranges(name: str) -> Randomisation:
    """The shipped ranges file ``name`` (:data:`~pushctl.task.env_config.RANGES`), read once."""
    return load_ranges(default_file(f"{name}.toml"))
