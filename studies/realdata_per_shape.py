"""Zhou et al.'s protocol on the recorded pushes: one fit per shape and surface on the
calibration split, every test push scored with its own group's fit (docs/realdata.md §5).

Run as ``python -m studies.realdata_per_shape --data DIR --out per_shape.csv
[--split-seed 0] [--friction-model polygon] [--facets 16] [--start fit.toml] [--force]``.
Per (surface, shape) the calibration pushes of that shape (both speeds) are fitted with
``pushctl realdata fit``'s grids (μ_c, the rim weight, μ_g): from scratch as that command
does, or, with ``--start``, from that surface's parameters in a ``realdata fit`` file
(rim weight first, then μ_c, then ±1 and ±0.05 around them, then μ_g), so a shape's fit is
never worse on its calibration pushes than its surface's. The test pushes of the group are
replayed with that fit. The CSV has one row per (surface, shape, speed) group of the test
split with the fit, our NMSE and Zhou's on the same pushes, then a row ``all`` (means over
groups); the Markdown table printed is docs/realdata.md's.
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import asdict, replace
from pathlib import Path

import pandas as pd

from pushctl.errors import ConfigError
from pushctl.files.output_guard import refuse_existing_files
from pushctl.files.provenance import provenance_line, write_csv
from pushctl.realdata.data import calibration_mask, load_pushes
from pushctl.realdata.fit import FitGrids, ReplayCache, fit_surfaces, read_friction
from pushctl.realdata.metrics import COMPONENTS, group_scores, overall, zhou_end
from pushctl.realdata.replay import ReplaySettings, SurfaceParameters


def per_shape_scores(
    data_dir: Path,
    seed: int,
    settings: ReplaySettings,
    grids: FitGrids | None = None,
    start: dict[str, SurfaceParameters] | None = None,
) -> pd.DataFrame:
    """One row per test group: its shape's fit on that surface (from scratch, or refined
    from ``start``'s parameters of that surface), our and Zhou's scores."""
    grids = grids or FitGrids()
    data = load_pushes(data_dir)
    pushes = data.pushes
    calibration = calibration_mask(pushes, seed)
    cache = ReplayCache(data.shapes, settings)
    rows = []
    for (surface, _), index in sorted(pushes.groupby(["surface", "shape"]).groups.items()):
        group = pushes.loc[index]
        own = calibration[pushes.index.get_indexer(index)]
        calibration_pushes = group[own].reset_index(drop=True)
        if start is None:
            fit = fit_surfaces(calibration_pushes, data.shapes, settings, grids=grids,
                               cache=cache)[surface]  # fmt: skip
        else:
            fit = refine(calibration_pushes, surface, start[surface], grids, cache)
        test = group[~own].reset_index(drop=True)
        ends = cache.ends(test, surface, fit["parameters"])
        ours = group_scores(test, ends)
        zhou = group_scores(test, zhou_end(test))
        for (_, a), (_, z) in zip(ours.iterrows(), zhou.iterrows(), strict=True):
            rows.append({**a.to_dict(), **asdict(fit["parameters"]),
                         "calibration_nmse": fit["calibration_nmse"],
                         "zhou_nmse": z["nmse"]})  # fmt: skip
    table = pd.DataFrame(rows)
    mean = overall(table)
    last = {"surface": "all", "shape": "all", "n": int(table["n"].sum()), **mean,
            "zhou_nmse": float(table["zhou_nmse"].mean())}  # fmt: skip
    return pd.concat([table, pd.DataFrame([last])], ignore_index=True)


def refine(
    pushes: pd.DataFrame,
    surface: str,
    start: SurfaceParameters,
    grids: FitGrids,
    cache: ReplayCache,
) -> dict:
    """Coordinate search from ``start`` on ``pushes`` (one shape on ``surface``): the rim
    weight over its grid and ``start``'s, μ_c over its grid, both ±1 / ±0.05, then μ_g;
    each line keeps the current point when nothing beats it. As ``fit_surfaces``' result."""
    scores: dict[SurfaceParameters, float] = {}

    def score(params: SurfaceParameters) -> float:
        if params not in scores:
            ends = cache.ends(pushes, surface, params)
            scores[params] = float(group_scores(pushes, ends)["nmse"].mean())
        return scores[params]

    def line(best: SurfaceParameters, name: str, values) -> SurfaceParameters:
        candidates = [best] + [replace(best, **{name: float(v)}) for v in values
                               if v > 0 or name == "rim_weight"]  # fmt: skip
        return min(candidates, key=score)

    best = line(start, "rim_weight", grids.rim_weight)
    best = line(best, "mu_contact", grids.mu_contact)
    best = line(best, "rim_weight", (best.rim_weight - 1.0, best.rim_weight + 1.0))
    mu = best.mu_contact
    best = line(best, "mu_contact", (round(mu - 0.05, 3), round(mu + 0.05, 3)))
    best = line(best, "mu_ground", grids.mu_ground)
    return {"parameters": best, "calibration_nmse": score(best), "evaluations": len(scores)}


def markdown(table: pd.DataFrame) -> str:
    """The docs table: per shape and surface (speeds pooled by mean), NMSE ours / Zhou's."""
    body = table[table["surface"] != "all"]
    lines = ["| surface | shape | μ_c | rim weight | NMSE | Zhou's |", "|---|---|---|---|---|---|"]
    for (surface, shape), part in body.groupby(["surface", "shape"]):
        lines.append(f"| {surface} | {shape} | {part['mu_contact'].iloc[0]:.2f} | "
                     f"{part['rim_weight'].iloc[0]:g} | {part['nmse'].mean():.3f} | "
                     f"{part['zhou_nmse'].mean():.3f} |")  # fmt: skip
    total = table[table["surface"] == "all"].iloc[0]
    parts = ", ".join(f"{c} {total[f'nmse_{c}']:.3f}" for c in COMPONENTS)
    lines.append(f"| all | | | | **{total['nmse']:.3f}** ({parts}) | {total['zhou_nmse']:.3f} |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m studies.realdata_per_shape", description=__doc__.splitlines()[0]
    )
    parser.add_argument("--data", type=Path, required=True)
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--split-seed", type=int, default=0)
    parser.add_argument("--friction-model", default="polygon")
    parser.add_argument("--facets", type=int, default=16)
    parser.add_argument("--start", type=Path, default=None, help="a realdata fit file")
    parser.add_argument("--force", action="store_true", help="overwrite an existing --out")
    args = parser.parse_args(argv)
    try:
        refuse_existing_files("--out", (args.out,), args.force)
        settings = ReplaySettings(friction_model=args.friction_model, facets=args.facets)
        start = None if args.start is None else read_friction(args.start)[0]
        table = per_shape_scores(args.data, args.split_seed, settings, start=start)
    except ConfigError as error:
        parser.exit(2, f"error: {error}\n")
    options = sys.argv[1:] if argv is None else argv
    recorded = [o for o in options if o != "--force"]
    command = " ".join(["python -m studies.realdata_per_shape", *recorded])
    write_csv(args.out, table, provenance_line(command))
    print(markdown(table))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
