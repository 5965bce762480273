"""Replaying recorded pushes with the polygon friction: time per push for each facet count,
side by side in one process (docs/performance.md).

Run as ``python -m benchmarks.realdata_replay --data DIR [--per-group 10] [--facets 8,16]
[--repeats 5] [--out FILE] [--force]``. The first ``--per-group`` pushes of every
(surface, shape, speed) group of ``DIR/mit/pushes.csv`` are replayed as ``pushctl realdata
score`` replays them (one worker, the world's step, 2 mm per step, 16 support points) at
fixed parameters (abs μ_c 0.25, plywood 0.2, μ_g 0.6, rim weight 3), once per facet count,
the counts taking turns ``--repeats`` times on one core (pinned). Per count: the median time
per push [ms] and its ratio to the first count's.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import pandas as pd

from benchmarks.engines import pinned_to_one_core
from pushctl.errors import ConfigError
from pushctl.files.output_guard import refuse_existing_files
from pushctl.files.provenance import provenance_line, write_csv
from pushctl.realdata.data import load_pushes
from pushctl.realdata.replay import ReplaySettings, SurfaceParameters, replay_pushes

PARAMETERS = {
    "abs": SurfaceParameters(mu_contact=0.25, mu_ground=0.6, rim_weight=3.0),
    "plywood": SurfaceParameters(mu_contact=0.2, mu_ground=0.6, rim_weight=3.0),
}
"""The replay's parameters per surface: near the fitted ones (docs/realdata.md)."""


def study(data_dir: Path, per_group: int, facets: list[int], repeats: int) -> pd.DataFrame:
    """The table of the module docstring."""
    data = load_pushes(data_dir)
    groups = ["surface", "shape", "speed_mm_s"]
    pushes = data.pushes.groupby(groups).head(per_group).reset_index(drop=True)
    params = {surface: PARAMETERS.get(surface, SurfaceParameters()) for surface in
              pushes["surface"].unique()}  # fmt: skip
    times: dict[int, list[float]] = {count: [] for count in facets}
    with pinned_to_one_core():
        for count in facets:  # compiled and warm before timing
            replay_pushes(pushes.head(1), data.shapes, params, ReplaySettings(facets=count))
        for _ in range(repeats):
            for count in facets:
                start = time.perf_counter()
                replay_pushes(pushes, data.shapes, params, ReplaySettings(facets=count))
                times[count].append((time.perf_counter() - start) / len(pushes) * 1e3)
    first = statistics.median(times[facets[0]])
    rows = []
    for count in facets:
        median = statistics.median(times[count])
        rows.append({"facets": count, "pushes": len(pushes), "ms_per_push": median,
                     f"over_{facets[0]}_gon": median / first})  # fmt: skip
    return pd.DataFrame(rows)


def main(argv: list[str] | None = None) -> int:
    doc = (__doc__ or "").splitlines()[0]
    parser = argparse.ArgumentParser(prog="python -m benchmarks.realdata_replay", description=doc)
    parser.add_argument("--data", type=Path, required=True, help="the recordings' directory")
    parser.add_argument("--per-group", type=int, default=10, help="pushes of each group")
    parser.add_argument("--facets", default="8,16", help="facet counts, the first the base")
    parser.add_argument("--repeats", type=int, default=5, help="turns of each count")
    parser.add_argument("--out", type=Path, default=None, help="also write the table as CSV")
    parser.add_argument("--force", action="store_true", help="overwrite an existing --out file")
    args = parser.parse_args(argv)
    parts = [part.strip() for part in args.facets.split(",")]
    if args.per_group < 1 or args.repeats < 1 or not all(part.isdigit() for part in parts):
        print(
            "error: --per-group and --repeats must be integers >= 1 and --facets integers "
            f"separated by commas (e.g. 8,16), got {args.per_group}, {args.repeats} and "
            f"{args.facets!r}",
            file=sys.stderr,
        )
        return 2
    try:
        refuse_existing_files("--out", [args.out], args.force)
        table = study(args.data, args.per_group, [int(part) for part in parts], args.repeats)
    except ConfigError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    print(table.to_string(index=False, float_format=lambda v: f"{v:.3g}"))
    if args.out is not None:
        command = (
            f"python -m benchmarks.realdata_replay --data {args.data} --per-group "
            f"{args.per_group} --facets {args.facets} --repeats {args.repeats}"
        )
        write_csv(args.out, table, provenance_line(command))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
