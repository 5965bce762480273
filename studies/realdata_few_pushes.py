"""How few pushes of a shape the fit never saw set its pressure prior: the leave-one-shape-
out folds' per-surface parameters, with the held-out shape's rim weight (and μ_c) refined on
its first K calibration pushes per surface (docs/realdata.md §5).

Run as ``python -m studies.realdata_few_pushes --data DIR --loso LOSO_DIR/loso.csv --out
few.csv [--pushes 10] [--split-seed 0] [--friction-model polygon] [--facets 16] [--force]``,
after ``pushctl realdata loso`` with the same split seed and model. Per held-out shape and
surface, starting from that fold's parameters (fitted without the shape), the rim weight
over the fit's grid and μ_c ±0.05 are chosen on the shape's first K calibration pushes of
that surface (push ids in order; both speeds); every other push of the shape is scored with
them. The CSV has one row per held-out shape (the K pushes per surface, the chosen
parameters, NMSE as ``pushctl realdata loso`` reports it, the fold's NMSE on the same pushes
and Zhou's), then a row ``all`` (means over groups).
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

from pushctl.errors import ConfigError
from pushctl.files.output_guard import refuse_existing_files
from pushctl.files.provenance import provenance_line, write_csv
from pushctl.realdata.data import calibration_mask, load_pushes
from pushctl.realdata.fit import FitGrids, ReplayCache
from pushctl.realdata.metrics import group_scores, overall, zhou_end
from pushctl.realdata.replay import ReplaySettings, SurfaceParameters


def fold_parameters(loso: pd.DataFrame, shape: str, surface: str) -> SurfaceParameters:
    """The parameters the fold without ``shape`` fitted for ``surface`` (loso.csv's row)."""
    row = loso[loso["shape"] == shape]
    if row.empty or f"{surface}_mu_contact" not in row:
        raise ConfigError(f"--loso: no fold without {shape!r} for surface {surface!r}")
    r = row.iloc[0]
    return SurfaceParameters(float(r[f"{surface}_mu_contact"]), float(r[f"{surface}_mu_ground"]),
                             float(r[f"{surface}_rim_weight"]))  # fmt: skip


def few_pushes_scores(
    data_dir: Path, loso: pd.DataFrame, pushes_per_surface: int, seed: int,
    settings: ReplaySettings, grids: FitGrids | None = None,
) -> pd.DataFrame:  # fmt: skip
    """One row per held-out shape, then ``all`` (see the module doc)."""
    grids = grids or FitGrids()
    data = load_pushes(data_dir)
    pushes = data.pushes
    calibration = calibration_mask(pushes, seed)
    cache = ReplayCache(data.shapes, settings)
    rows, ours, fold, scored = [], [], [], []
    for shape in sorted(pushes["shape"].unique()):
        record: dict[str, object] = {"shape": shape}
        for surface in sorted(pushes.loc[pushes["shape"] == shape, "surface"].unique()):
            here = ((pushes["shape"] == shape) & (pushes["surface"] == surface)).to_numpy()
            ids = pushes.loc[here & calibration, "push_id"].astype(str).sort_values()
            chosen = pushes["push_id"].astype(str).isin(ids.iloc[:pushes_per_surface]).to_numpy()
            few = pushes[here & chosen].reset_index(drop=True)
            rest = pushes[here & ~chosen].reset_index(drop=True)
            start = fold_parameters(loso, shape, surface)
            best = _refine(few, surface, start, grids, cache)
            record |= {f"{surface}_pushes": len(few), f"{surface}_mu_contact": best.mu_contact,
                       f"{surface}_rim_weight": best.rim_weight}  # fmt: skip
            ours.append(cache.ends(rest, surface, best))
            fold.append(cache.ends(rest, surface, start))
            scored.append(rest)
        rows.append(record)
    table = pd.concat(scored, ignore_index=True)
    ends, fold_ends = np.vstack(ours), np.vstack(fold)
    out = []
    for record in rows:
        mask = (table["shape"] == record["shape"]).to_numpy()
        out.append({**record, **_summary(table[mask].reset_index(drop=True), ends[mask],
                                         fold_ends[mask])})  # fmt: skip
    out.append({"shape": "all", **_summary(table, ends, fold_ends)})
    return pd.DataFrame(out)


def _summary(pushes: pd.DataFrame, ends: np.ndarray, fold_ends: np.ndarray) -> dict:
    zhou = zhou_end(pushes)
    return {
        "n": len(pushes),
        **overall(group_scores(pushes, ends)),
        "fold_nmse": overall(group_scores(pushes, fold_ends))["nmse"],
        "zhou_nmse": np.nan if zhou is None else overall(group_scores(pushes, zhou))["nmse"],
    }


def _refine(pushes, surface, start, grids, cache) -> SurfaceParameters:
    """The rim weight over ``grids`` and ±1, then μ_c ±0.05, from ``start`` (kept on ties)."""

    def score(params: SurfaceParameters) -> float:
        return float(group_scores(pushes, cache.ends(pushes, surface, params))["nmse"].mean())

    def line(best, name, values):
        candidates = [best] + [replace(best, **{name: float(v)}) for v in values
                               if v > 0 or name == "rim_weight"]  # fmt: skip
        return min(candidates, key=score)

    best = line(start, "rim_weight", grids.rim_weight)
    best = line(best, "rim_weight", (best.rim_weight - 1.0, best.rim_weight + 1.0))
    mu = best.mu_contact
    return line(best, "mu_contact", (round(mu - 0.05, 3), round(mu + 0.05, 3)))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m studies.realdata_few_pushes", description=__doc__.splitlines()[0]
    )
    parser.add_argument("--data", type=Path, required=True)
    parser.add_argument("--loso", type=Path, required=True, help="pushctl realdata loso's loso.csv")
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--pushes", type=int, default=10)
    parser.add_argument("--split-seed", type=int, default=0)
    parser.add_argument("--friction-model", default="polygon")
    parser.add_argument("--facets", type=int, default=16)
    parser.add_argument("--force", action="store_true", help="overwrite an existing --out")
    args = parser.parse_args(argv)
    try:
        refuse_existing_files("--out", (args.out,), args.force)
        loso = pd.read_csv(args.loso, comment="#")
        settings = ReplaySettings(friction_model=args.friction_model, facets=args.facets)
        table = few_pushes_scores(args.data, loso, args.pushes, args.split_seed, settings)
    except (ConfigError, FileNotFoundError) as error:
        parser.exit(2, f"error: {error}\n")
    options = [o for o in (sys.argv[1:] if argv is None else argv) if o != "--force"]
    write_csv(args.out, table, provenance_line(" ".join(["python -m studies.realdata_few_pushes",
                                                         *options])))  # fmt: skip
    with pd.option_context("display.width", 200, "display.max_columns", 30):
        print(table.round(3).to_string(index=False))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
