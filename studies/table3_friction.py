"""Table III on the ``sim`` plant with the polygon ground friction beside the slip box: do
the ratios, the failed pushes or the law against PD-only change? (docs/model.md)

Run as ``python -m studies.table3_friction --out table3_friction.csv [--trials 50]
[--facets 8] [--force]``. PD-only and the feedback law push the evaluation stream's trials
(the shipped policies hold the law, so RL's rows would be the law's) once with the world's
default friction and once with ``friction_model="polygon"``: the same scenarios, plans and
plant unknowns, only the world's ground rows differ. The CSV has one row per friction model,
object and profile: the mean translation and angle errors [%] of PD-only and the law, the
law's ratios to PD-only, the failed pushes of each (angle error above 20 % or translation
above 3 %), and the law − PD difference paired over the trials with its 95 % half-width;
the Markdown table printed is docs/model.md's.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from functools import partial
from pathlib import Path

import pandas as pd

from pushctl.errors import ConfigError
from pushctl.files.output_guard import refuse_existing_files
from pushctl.files.provenance import provenance_line, write_csv
from pushctl.report.tables import ci95_halfwidth

FAILED_ANGLE, FAILED_TRANSLATION = 20.0, 3.0
"""A failed push [%]: angle error above 20 % or translation error above 3 % (docs/results.md)."""
MODELS = ("slip_box", "polygon")


@contextmanager
def world_friction(model: str, facets: int) -> Iterator[None]:
    """Every world the episodes of this process build gets ``model`` ground friction."""
    import pushctl.episode.runner as runner

    original = runner.make_world
    runner.make_world = partial(original, friction_model=model, facets=facets)
    try:
        yield
    finally:
        runner.make_world = original


def run(trials: int, facets: int) -> pd.DataFrame:
    """The per-trial rows of PD-only and the law on ``sim``, for each friction model."""
    from pushctl.evaluation.evaluate import evaluate
    from pushctl.evaluation.trials import TrialSpec

    spec = TrialSpec(plants=("sim",), controllers=("pd", "feedback"), trials=trials)
    frames = []
    for model in MODELS:
        with world_friction(model, facets):
            rows = evaluate(spec, workers=1).trials
        frames.append(rows.assign(friction_model=model))
    return pd.concat(frames, ignore_index=True)


def table(rows: pd.DataFrame) -> pd.DataFrame:
    """One row per friction model, object and profile (see the module doc)."""
    out = []
    for (model, obj, profile), cell in rows.groupby(["friction_model", "object", "profile"],
                                                    sort=False):  # fmt: skip
        pd_rows = cell[cell["controller"] == "pd"].set_index("trial")
        law = cell[cell["controller"] == "feedback"].set_index("trial")
        record = {"friction_model": model, "object": obj, "profile": profile, "n": len(law)}
        for metric in ("translation", "angle"):
            a, b = pd_rows[f"{metric}_error_pct"], law[f"{metric}_error_pct"]
            record |= {f"{metric}_pd": a.mean(), f"{metric}_law": b.mean(),
                       f"{metric}_law_pd": b.mean() / a.mean(),
                       f"{metric}_law_minus_pd": (b - a).mean(),
                       f"{metric}_law_minus_pd_ci95": ci95_halfwidth(b - a)}  # fmt: skip
        for name, frame in (("pd", pd_rows), ("law", law)):
            failed = (frame["angle_error_pct"] > FAILED_ANGLE) | (
                frame["translation_error_pct"] > FAILED_TRANSLATION
            )
            record[f"failed_{name}"] = int(failed.sum())
        out.append(record)
    return pd.DataFrame(out)


def markdown(summary: pd.DataFrame) -> str:
    """Both models side by side per cell: law/PD ratios, failed pushes, law − PD."""
    lines = [
        "| object | profile | friction | translation PD / law [%] | law/PD | angle PD / law [%] "
        "| law/PD | failed PD, law | law − PD translation, angle [points] |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for _, r in summary.iterrows():
        lines.append(
            f"| {r['object']} | {r['profile']} | {r['friction_model']} | "
            f"{r['translation_pd']:.3g} / {r['translation_law']:.3g} | "
            f"{r['translation_law_pd']:.2f} | {r['angle_pd']:.3g} / {r['angle_law']:.3g} | "
            f"{r['angle_law_pd']:.2f} | {r['failed_pd']}, {r['failed_law']} | "
            f"{r['translation_law_minus_pd']:+.3f} ± {r['translation_law_minus_pd_ci95']:.3f}, "
            f"{r['angle_law_minus_pd']:+.3f} ± {r['angle_law_minus_pd_ci95']:.3f} |"
        )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m studies.table3_friction", description=__doc__.splitlines()[0]
    )
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--trials", type=int, default=50)
    parser.add_argument("--facets", type=int, default=8)
    parser.add_argument("--force", action="store_true", help="overwrite an existing --out")
    args = parser.parse_args(argv)
    try:
        refuse_existing_files("--out", (args.out,), args.force)
        summary = table(run(args.trials, args.facets))
    except ConfigError as error:
        parser.exit(2, f"error: {error}\n")
    options = [o for o in (sys.argv[1:] if argv is None else argv) if o != "--force"]
    command = " ".join(["python -m studies.table3_friction", *options])
    write_csv(args.out, summary, provenance_line(command))
    print(markdown(summary))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
