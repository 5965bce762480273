"""The names and values ``evaluate`` and ``train`` accept, checked before the core is
imported (torch, the simulator: seconds), so a typo is refused at once. The names are the
core's own (tests/cli/test_early_checks.py holds them equal; the controllers are read from
their registry); the core checks them again.
"""

from __future__ import annotations

from pathlib import Path

from pushctl.errors import ConfigError

OBJECTS = ("cube", "wedge")
""":data:`pushctl.objects.OBJECT_NAMES`; a TOML object file is accepted too."""
PROFILES = ("constant", "trapezoid", "chirp")
""":data:`pushctl.planning.PROFILE_NAMES`."""
PLANTS = ("sim", "proxy", "mujoco")
""":data:`pushctl.config.PLANT_KINDS`; ``both`` and ``all`` select several."""
STREAMS = ("evaluation", "tuning")
""":data:`pushctl.evaluation.trials.STREAMS_EVALUATED`."""
MAX_TRIALS = 100_000
""":data:`pushctl.evaluation.trials.SEEDS_PER_EVALUATION`: trials per cell at most."""
PRESETS = ("quick", "paper")
""":data:`pushctl.rl.presets.PRESET_NAMES`; a preset .toml file is accepted too."""


def check_evaluate_options(
    object_name: str,
    profile: str,
    trials: int,
    controller: str,
    plant: str,
    scenario_block: int,
    stream: str,
    workers: int,
    out: Path,
) -> None:
    """ConfigError (one line) for the first option of ``pushctl evaluate`` that cannot run."""
    if not object_name.lower().endswith(".toml"):
        _names("--object", object_name, OBJECTS, "all")
    _names("--profile", profile, PROFILES, "all")
    from pushctl.controllers import controller_names  # the registry: light, no numpy

    _names("--controller", controller, controller_names(), "all")
    if plant not in (*PLANTS, "both", "all"):
        raise ConfigError(f"unknown --plant {plant!r}; accepted: {', '.join(PLANTS)}, both or all")
    if not 1 <= trials <= MAX_TRIALS:
        raise ConfigError(f"--trials must be an integer in 1 … {MAX_TRIALS}, got {trials!r}")
    if scenario_block < 0:
        raise ConfigError(f"--scenario-block must be an integer >= 0, got {scenario_block}")
    if stream not in STREAMS:
        raise ConfigError(f"unknown --stream {stream!r}; accepted: {', '.join(STREAMS)}")
    if not 1 <= workers <= 8:
        raise ConfigError(f"--workers must be an integer in 1 … 8, got {workers!r}")
    if out.exists() and not out.is_dir():
        raise ConfigError(f"--out {out} is a file; give a directory")


def check_train_options(
    preset: str | None, seed: int | None, out: Path | None, resume: bool, force: bool
) -> None:
    """ConfigError (one line) for the first option of ``pushctl train`` that cannot run."""
    if resume and force:
        raise ConfigError("--resume and --force exclude each other: continue, or start over")
    if seed is not None and seed < 0:
        raise ConfigError(f"--seed must be an integer >= 0, got {seed}")
    if preset is not None and preset not in PRESETS:
        if not preset.endswith(".toml"):
            raise ConfigError(
                f"unknown preset {preset!r}; accepted: {', '.join(PRESETS)} or a .toml file"
            )
        if not Path(preset).is_file():
            raise ConfigError(f"preset file {preset} does not exist")
    if out is not None and out.exists() and not out.is_dir():
        raise ConfigError(f"--out {out} is a file; give a directory")


def _names(option: str, value: str, names: tuple[str, ...], every: str) -> None:
    chosen = names if value == every else tuple(value.split(","))
    if not all(name in names for name in chosen):
        raise ConfigError(
            f"unknown {option} {value!r}; accepted: {', '.join(names)} or {every} "
            "(or several, comma-separated)"
        )
