"""Fitting the per-surface parameters on the calibration split, and their TOML file.

Per surface, the calibration pushes' mean NMSE (the protocol of
:mod:`pushctl.realdata.metrics`) is minimised by coordinate search over fixed grids
(:class:`FitGrids`): μ_c first, then the pressure prior's rim weight, then the rim weight
±1 and μ_c ±0.05 around the best values, then μ_g. The grids are part of the method (no
randomness): one data set, split and seed give one file.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import asdict, dataclass, replace
from pathlib import Path

import numpy as np
import pandas as pd
import tomllib

from pushctl.errors import ConfigError, reason
from pushctl.ranges import check_range
from pushctl.realdata.metrics import group_scores
from pushctl.realdata.replay import ReplaySettings, SurfaceParameters, replay_pushes


@dataclass(frozen=True)
class FitGrids:
    """The coordinate search's grids. μ_g hardly matters when the motion is quasi-static
    (it scales every friction force alike); it is searched last, over a coarse grid, to
    show how little it moves the score."""

    mu_contact: tuple[float, ...] = (0.1, 0.2, 0.3, 0.4, 0.6)
    rim_weight: tuple[float, ...] = (-2.0, 0.0, 2.0, 4.0, 6.0, 8.0)
    mu_ground: tuple[float, ...] = (0.15, 0.3, 0.6)


class ReplayCache:
    """End poses of pushes already replayed, by parameters and push id: fits over
    overlapping pushes (the leave-one-shape-out folds) replay each push once per parameter
    set. A push's prediction depends only on its own row and the parameters."""

    def __init__(
        self, shapes: Mapping[str, np.ndarray], settings: ReplaySettings, workers: int = 1
    ) -> None:
        self.shapes, self.settings, self.workers = shapes, settings, workers
        self._ends: dict[SurfaceParameters, dict[str, np.ndarray]] = {}
        self.replayed = 0

    def ends(self, pushes: pd.DataFrame, surface: str, params: SurfaceParameters) -> np.ndarray:
        """End poses (N, 3) of ``pushes`` (all on ``surface``) under ``params``."""
        known = self._ends.setdefault(params, {})
        ids = pushes["push_id"].tolist()
        missing = [i for i, push_id in enumerate(ids) if push_id not in known]
        if missing:
            rows = pushes.iloc[missing].reset_index(drop=True)
            new = replay_pushes(rows, self.shapes, {surface: params}, self.settings, self.workers)
            known.update(zip(rows["push_id"], new, strict=True))
            self.replayed += len(missing)
        return np.array([known[push_id] for push_id in ids]).reshape(-1, 3)


def fit_surfaces(
    pushes: pd.DataFrame,
    shapes: Mapping[str, np.ndarray],
    settings: ReplaySettings,
    workers: int = 1,
    progress: Callable[[str], None] | None = None,
    grids: FitGrids = FitGrids(),
    cache: ReplayCache | None = None,
) -> dict[str, dict]:
    """Fit each surface in ``pushes`` (the calibration split). Returns surface →
    {"parameters": SurfaceParameters, "calibration_nmse": float, "evaluations": int}.
    ``cache`` (built with the same shapes and settings) reuses earlier replays."""
    cache = cache if cache is not None else ReplayCache(shapes, settings, workers)
    fits = {}
    for surface in sorted(pushes["surface"].unique()):
        part = pushes[pushes["surface"] == surface].reset_index(drop=True)
        scores: dict[SurfaceParameters, float] = {}

        def score(params: SurfaceParameters, part=part, scores=scores, surface=surface) -> float:
            if params not in scores:
                end = cache.ends(part, surface, params)
                scores[params] = float(group_scores(part, end)["nmse"].mean())
                if progress is not None and scores[params] == min(scores.values()):
                    progress(
                        f"{surface}: best so far μ_c {params.mu_contact:g}, μ_g "
                        f"{params.mu_ground:g}, rim weight {params.rim_weight:g}: NMSE "
                        f"{scores[params]:.4f} ({len(scores)} tried)"
                    )
            return scores[params]

        best = SurfaceParameters()
        best = _line(score, best, "mu_contact", grids.mu_contact)
        best = _line(score, best, "rim_weight", grids.rim_weight)
        rim = best.rim_weight
        best = _line(score, best, "rim_weight", (rim - 1.0, rim, rim + 1.0))
        mu = best.mu_contact
        best = _line(score, best, "mu_contact", (round(mu - 0.05, 3), mu, round(mu + 0.05, 3)))
        best = _line(score, best, "mu_ground", grids.mu_ground)
        fits[surface] = {"parameters": best, "calibration_nmse": score(best),
                         "evaluations": len(scores)}  # fmt: skip
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
        raise ConfigError(f"--friction: {path} is not a friction fit ({reason(error)})") from None
    if not params:
        raise ConfigError(f"--friction: {path} names no surface")
    for surface, values in params.items():
        for name in ("mu_contact", "mu_ground"):
            check_range("friction coefficient", getattr(values, name),
                        f"--friction: {path}: surface {surface} {name}: ")  # fmt: skip
    split = data.get("split", {})
    return params, settings, split if isinstance(split, dict) else {}
