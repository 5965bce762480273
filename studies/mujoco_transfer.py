"""How the shipped policy transfers to MuJoCo: RL/PD per cell on ``mujoco`` beside ``sim`` and
``proxy``.

Reads a ``trials.csv`` of ``pushctl evaluate --plant mujoco`` (or ``all``) and, for the other
plants, the same file's rows or the shipped ``results/table3.csv`` and ``results/table4.csv``;
the means come from :func:`pushctl.report.tables.summarise`, the report's own. Run as
``python -m studies.mujoco_transfer --trials runs/…/trials.csv [--docs docs/mujoco.md]``.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import pandas as pd

from pushctl.files.provenance import write_atomic
from pushctl.report.tables import summarise
from studies.mujoco_validation import replace_block

BEGIN, END = "<!-- BEGIN transfer table -->", "<!-- END transfer table -->"
METRICS = (
    ("translation_error_pct", "translation_error", "transl. %"),
    ("angle_error_pct", "angle_error", "angle %"),
    ("force_error", "force_error", "force N"),
)
SHIPPED = Path("results")


def mujoco_table(trials: pd.DataFrame) -> pd.DataFrame:
    """Per (object, profile): PD-only and RL-assisted means of :data:`METRICS` on mujoco,
    the number of trials, the share of steps the residual's gate was open and the RL rows'
    contact-loss fraction."""
    columns = {
        f"{short}_{controller}": (metric, "mujoco", controller)
        for metric, short, _ in METRICS
        for controller in ("pd", "rl")
    }
    columns["gate_rl"] = ("gate_open_fraction", "mujoco", "rl")
    columns["lost_rl"] = ("contact_loss_fraction", "mujoco", "rl")
    columns["lost_pd"] = ("contact_loss_fraction", "mujoco", "pd")
    table = summarise(trials, columns)
    values = table.values[["object", "profile", *columns]]
    values["n"] = table.counts["translation_error_pd"]
    return values


def shipped_ratios(results: Path = SHIPPED) -> pd.DataFrame:
    """RL/PD per cell on sim (table3: translation, angle; table4: force) and proxy (force),
    from the shipped tables."""
    t3 = pd.read_csv(results / "table3.csv", comment="#")
    t4 = pd.read_csv(results / "table4.csv", comment="#")
    merged = t3.merge(t4, on=["object", "profile"])
    out = merged[["object", "profile"]].copy()
    out["translation_sim"] = merged["translation_error_rl"] / merged["translation_error_pd"]
    out["angle_sim"] = merged["angle_error_rl"] / merged["angle_error_pd"]
    for plant in ("sim", "proxy"):
        out[f"force_{plant}"] = (
            merged[f"force_error_rl_{plant}"] / merged[f"force_error_pd_{plant}"]
        )
    return out


def _f(value: float, digits: int = 3) -> str:
    return "–" if not math.isfinite(value) else f"{value:.{digits}g}"


def transfer_markdown(trials_path: Path, results: Path = SHIPPED) -> str:
    """The generated block: the mujoco means and RL/PD beside sim's and proxy's."""
    trials = pd.read_csv(trials_path, comment="#")
    with trials_path.open(encoding="utf-8") as handle:
        made_by = handle.readline().strip().removeprefix("# made by: ").split(";")[0]
    table = mujoco_table(trials).merge(shipped_ratios(results), on=["object", "profile"])
    lines = [
        BEGIN,
        f"From `{trials_path}` (made by `{made_by}`) and the shipped `results/table3.csv`, "
        "`results/table4.csv` (sim, proxy: 50 trials per cell). Regenerate with "
        f"`python -m studies.mujoco_transfer --trials {trials_path} --docs docs/mujoco.md`.",
        "",
        "| object | profile | n | mujoco transl. % PD / RL | angle % PD / RL | force N PD / RL "
        "| gate open (RL) | contact lost PD / RL | RL/PD transl. sim / mujoco "
        "| RL/PD angle sim / mujoco | RL/PD force sim / proxy / mujoco |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for _, r in table.iterrows():
        ratio = {
            short: r[f"{short}_rl"] / r[f"{short}_pd"] if r[f"{short}_pd"] else math.nan
            for _, short, _ in METRICS
        }
        lines.append(
            f"| {r['object']} | {r['profile']} | {int(r['n'])} "
            f"| {_f(r['translation_error_pd'])} / {_f(r['translation_error_rl'])} "
            f"| {_f(r['angle_error_pd'])} / {_f(r['angle_error_rl'])} "
            f"| {_f(r['force_error_pd'])} / {_f(r['force_error_rl'])} "
            f"| {100 * r['gate_rl']:.0f} % | {100 * r['lost_pd']:.1f} / {100 * r['lost_rl']:.1f} % "
            f"| {_f(r['translation_sim'])} / {_f(ratio['translation_error'])} "
            f"| {_f(r['angle_sim'])} / {_f(ratio['angle_error'])} "
            f"| {_f(r['force_sim'])} / {_f(r['force_proxy'])} / {_f(ratio['force_error'])} |"
        )
    lines.append(END)
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m studies.mujoco_transfer", description=__doc__.splitlines()[0]
    )
    parser.add_argument("--trials", type=Path, required=True, help="trials.csv with mujoco rows")
    parser.add_argument("--results", type=Path, default=SHIPPED, help="shipped tables' folder")
    parser.add_argument("--docs", type=Path, help="page whose transfer block to rewrite")
    args = parser.parse_args(argv)
    block = transfer_markdown(args.trials, args.results)
    sys.stdout.write(block)
    if args.docs is not None:
        text = args.docs.read_text(encoding="utf-8") if args.docs.exists() else ""
        page = replace_block(text, block, BEGIN, END)
        write_atomic(args.docs, lambda tmp: tmp.write_text(page, encoding="utf-8"))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
