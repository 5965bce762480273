"""Fitting the per-surface parameters on the calibration split, and their TOML file.

Per surface, the calibration pushes' mean NMSE (the protocol of
:mod:`pushctl.realdata.metrics`) is minimised by coordinate search over a fixed grid:
μ_c first, then the pressure prior's rim weight, then μ_c again around its best value,
then μ_g. The grids are part of the method (no randomness): one data set, split and seed
give one file.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import asdict, replace
from pathlib import Path

import numpy as np
import pandas as pd
import tomllib

from pushctl.errors import ConfigError
from pushctl.realdata.metrics import group_scores
from pushctl.realdata.replay import ReplaySettings, SurfaceParameters, replay_pushes

MU_CONTACT_GRID = (0.1, 0.2, 0.3, 0.4, 0.6)
RIM_WEIGHT_GRID = (-2.0, 0.0, 2.0)
MU_GROUND_GRID = (0.15, 0.3, 0.6)
"""μ_g hardly matters when the motion is quasi-static (it scales every friction force
alike); it is searched last, over a coarse grid, to show how little it moves the score."""


def fit_surfaces(
    pushes: pd.DataFrame,
    shapes: Mapping[str, np.ndarray],
    settings: ReplaySettings,
    workers: int = 1,
    progress: Callable[[str], None] | None = None,
) -> dict[str, dict]:
    """Fit each surface in ``pushes`` (the calibration split). Returns surface →
    {"parameters": SurfaceParameters, "calibration_nmse": float, "evaluations": int}."""
    fits = {}
    for surface in sorted(pushes["surface"].unique()):
        part = pushes[pushes["surface"] == surface].reset_index(drop=True)
        cache: dict[SurfaceParameters, float] = {}

        def score(params: SurfaceParameters, part=part, cache=cache, surface=surface) -> float:
            if params not in cache:
                end = replay_pushes(part, shapes, {surface: params}, settings, workers)
                cache[params] = float(group_scores(part, end)["nmse"].mean())
                if progress is not None:
                    progress(f"{surface}: {params} -> NMSE {cache[params]:.4f}")
            return cache[params]

        best = SurfaceParameters()
        best = _line(score, best, "mu_contact", MU_CONTACT_GRID)
        best = _line(score, best, "rim_weight", RIM_WEIGHT_GRID)
        rim = best.rim_weight
        best = _line(score, best, "rim_weight", (rim - 1.0, rim, rim + 1.0))
        mu = best.mu_contact
        best = _line(score, best, "mu_contact", (round(mu - 0.05, 3), mu, round(mu + 0.05, 3)))
        best = _line(score, best, "mu_ground", MU_GROUND_GRID)
        fits[surface] = {"parameters": best, "calibration_nmse": score(best),
                         "evaluations": len(cache)}  # fmt: skip
    return fits


def _line(score, start: SurfaceParameters, name: str, grid) -> SurfaceParameters:
    """The best of ``start`` with ``name`` set to each grid value (ties: the first)."""
    candidates = [replace(start, **{name: float(v)}) for v in grid if v > 0 or name == "rim_weight"]
    values = [score(c) for c in candidates]
    return candidates[int(np.argmin(values))]


def friction_toml(fits: Mapping[str, dict], settings: ReplaySettings, header: list[str]) -> str:
    """The fit as TOML: ``header`` comment lines (provenance), the replay settings, one
    table per surface."""
    lines = [f"# {h}" if not h.startswith("#") else h for h in header]
    lines += ["", "[settings]"]
    lines += [f"{k} = {_value(v)}" for k, v in asdict(settings).items()]
    for surface, fit in fits.items():
        lines += ["", f"[surface.{surface}]"]
        lines += [f"{k} = {_value(v)}" for k, v in asdict(fit["parameters"]).items()]
        lines += [f"calibration_nmse = {fit['calibration_nmse']:.6f}"]
    return "\n".join(lines) + "\n"


def _value(v) -> str:
    return f'"{v}"' if isinstance(v, str) else repr(v)


def read_friction(path: Path) -> tuple[dict[str, SurfaceParameters], ReplaySettings, dict]:
    """Per-surface parameters, the replay settings and the split (``[split]``: seed,
    excluded shapes, calibration digest; may be empty) from a fit file."""
    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"--friction: {path} does not exist")
    try:
        data = tomllib.loads(path.read_text())
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as error:
        raise ConfigError(f"--friction: {path} is not valid TOML ({error})") from None
    try:
        settings = ReplaySettings(**data.get("settings", {}))
        params = {
            name: SurfaceParameters(**{k: float(v) for k, v in table.items()
                                       if k in SurfaceParameters.__dataclass_fields__})
            for name, table in data["surface"].items()
        }  # fmt: skip
    except (KeyError, TypeError, ValueError, AttributeError) as error:
        raise ConfigError(f"--friction: {path} is not a friction fit ({error})") from None
    if not params:
        raise ConfigError(f"--friction: {path} names no surface")
    split = data.get("split", {})
    return params, settings, split if isinstance(split, dict) else {}
