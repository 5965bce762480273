"""Training presets: the shipped ``quick`` and ``paper`` (:mod:`pushctl.defaults`) or any TOML
file with the same tables, each holding ``[train]`` (:class:`TrainConfig`), ``[env]``
(:class:`~pushctl.task.env_config.EnvConfig`) and ``[ddpg]``
(:class:`~pushctl.rl.config.DDPGConfig`)."""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields
from pathlib import Path
from typing import Any

from pushctl.defaults import default_file
from pushctl.errors import ConfigError
from pushctl.files.toml import check_keys, read_toml
from pushctl.ranges import check_range
from pushctl.rl.config import DDPGConfig
from pushctl.rl.validate import SELECTION_RULES
from pushctl.task.env_config import EnvConfig

PRESET_NAMES = ("quick", "paper")
"""The presets shipped with pushctl (package data, :mod:`pushctl.defaults`: ``train_quick.toml``,
``train_paper.toml``)."""


@dataclass(frozen=True)
class TrainConfig:
    """The training loop's settings.

    ``episodes``: episodes to run (each one push of ``EnvConfig.duration``).
    ``checkpoint_every``: episodes between checkpoints. ``pd_every``: run PD-only on the
    episode's scenario every n-th episode for the training curves (1: every episode).
    ``episodes_per_round``: episodes run at once with one actor (see
    :mod:`pushctl.rl.train`); part of the learning schedule. ``workers``: collector processes
    running them beside the learner (0: in the learner's process); the results do not
    depend on it. ``validate_every``: score the deterministic
    actor on the validation set every n-th episode and keep the best for ``policy.pt``
    (0: never; keep the last); ``validation_per_cell``: its scenarios per object × profile
    (:mod:`pushctl.rl.validate`); ``select_on``: what a kept actor must beat PD-only on
    (:data:`~pushctl.rl.validate.SELECTION_RULES`).
    """

    episodes: int = 40
    checkpoint_every: int = 10
    pd_every: int = 1
    episodes_per_round: int = 1
    workers: int = 1
    validate_every: int = 0
    validation_per_cell: int = 2
    select_on: str = "force_and_translation"

    def __post_init__(self) -> None:
        for name, low in (
            ("episodes", 1),
            ("checkpoint_every", 1),
            ("pd_every", 1),
            ("episodes_per_round", 1),
            ("validate_every", 0),
            ("validation_per_cell", 1),
        ):
            _check_int(name, getattr(self, name), low)
        _check_int("workers", self.workers, 0)
        check_range("training episodes", self.episodes, "train episodes: ")
        if self.select_on not in SELECTION_RULES:
            raise ConfigError(
                f"train select_on must be one of {', '.join(SELECTION_RULES)}, "
                f"got {self.select_on!r}"
            )
        if self.workers > 8:
            raise ConfigError(f"train workers must be an integer in 0..8, got {self.workers!r}")


@dataclass(frozen=True)
class Preset:
    """A whole training set-up; ``name`` is the preset's name or its file's path."""

    name: str
    train: TrainConfig
    env: EnvConfig
    ddpg: DDPGConfig

    def to_dict(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "train": asdict(self.train),
            "env": self.env.to_dict(),
            "ddpg": self.ddpg.to_dict(),
        }

    @classmethod
    def from_dict(cls, values: dict[str, Any]) -> Preset:
        """From :meth:`to_dict` (a checkpoint's copy)."""
        return cls(
            name=str(values["name"]),
            train=_train_config(values["train"]),
            env=EnvConfig.from_saved(values["env"]),
            ddpg=DDPGConfig.from_mapping(values["ddpg"]),
        )


def preset_path(name_or_path: str) -> Path:
    """``quick``/``paper`` → the shipped ``train_<name>.toml``; a path ending in .toml as
    is; anything else is a ConfigError naming the accepted values."""
    if name_or_path in PRESET_NAMES:
        return default_file(f"train_{name_or_path}.toml")
    if name_or_path.endswith(".toml"):
        return Path(name_or_path)
    raise ConfigError(
        f"unknown preset {name_or_path!r}; accepted: {', '.join(PRESET_NAMES)} or a .toml file"
    )


def load_preset(name_or_path: str) -> Preset:
    """Read a preset; ConfigError naming the file for a missing, corrupt or invalid one."""
    path = preset_path(name_or_path)
    table = read_toml(path, "preset file")
    try:
        check_keys(table, ["train", "env", "ddpg"], "preset")
        return Preset(
            name=name_or_path,
            train=_train_config(_table(table, "train")),
            env=EnvConfig.from_mapping(_table(table, "env")),
            ddpg=DDPGConfig.from_mapping(_table(table, "ddpg")),
        )
    except ConfigError as exc:
        raise ConfigError(f"preset file {path}: {exc}") from None


def _table(table: dict[str, Any], name: str) -> dict[str, Any]:
    values = table.get(name, {})
    if not isinstance(values, dict):
        raise ConfigError(f"[{name}] must be a table")
    return values


def _train_config(values: dict[str, Any]) -> TrainConfig:
    check_keys(values, [item.name for item in fields(TrainConfig)], "[train]", all_required=False)
    return TrainConfig(**values)


def _check_int(name: str, value: object, low: int) -> None:
    if not isinstance(value, int) or isinstance(value, bool) or value < low:
        raise ConfigError(f"train {name} must be an integer >= {low}, got {value!r}")
