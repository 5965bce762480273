"""PD-only against RL-assisted on held-out scenarios: issue 5's acceptance check.

``python -m pushctl.evaluation.heldout --policy runs/paper/policy.pt --per-cell 20`` draws
``per-cell`` scenarios per object × profile from the *evaluation* stream (seeds 0 …
per-cell − 1; training draws from its own stream), with plant parameters from the ``sim``
ranges, runs PD-only and the residual policy on each (paired: same goal, same plant, same
plan), and writes one row per episode and controller to ``--out``. It prints the mean per
object × profile and over all.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import pandas as pd

from pushctl.control.gains import PDGains, load_gains
from pushctl.episode.metrics import compute_metrics
from pushctl.episode.runner import Episode
from pushctl.errors import PushctlError
from pushctl.objects import OBJECT_NAMES
from pushctl.planning import PROFILE_NAMES
from pushctl.provenance import provenance_line, write_csv
from pushctl.rl.policy import TrainedPolicy, evaluation_env, load_policy, run_policy

SUMMARY_COLUMNS = ("translation_error_pct", "angle_error_pct", "force_error", "torque_error")


def heldout_table(
    policy: TrainedPolicy,
    per_cell: int,
    gains: PDGains | None = None,
    plant: str = "sim",
    objects: tuple[str, ...] = OBJECT_NAMES,
    profiles: tuple[str, ...] = PROFILE_NAMES,
) -> pd.DataFrame:
    """Rows (object, profile, seed, controller ∈ {pd, rl}, scenario, metrics, gate share)."""
    gains = gains if gains is not None else load_gains()
    env = evaluation_env(policy, gains, plant)
    rows = []
    for obj in objects:
        for profile in profiles:
            for seed in range(per_cell):
                options = {"object": obj, "profile": profile, "scenario_seed": seed}
                rl_trace = run_policy(env, policy.actor, options)
                pd_trace = Episode(env.scenario, gains, plan=env.plan).run()
                plant_parameters = env.scenario.plant
                for controller, trace in (("pd", pd_trace), ("rl", rl_trace)):
                    rows.append(
                        {
                            "object": obj,
                            "profile": profile,
                            "seed": seed,
                            "controller": controller,
                            "mu_ground": plant_parameters.mu_ground,
                            "mu_contact": plant_parameters.mu_contact,
                            **compute_metrics(trace).as_dict(),
                        }
                    )
    return pd.DataFrame(rows)


def summary(table: pd.DataFrame) -> pd.DataFrame:
    """Mean of :data:`SUMMARY_COLUMNS` per object × profile × controller, and over all."""
    columns = list(SUMMARY_COLUMNS)
    cells = table.groupby(["object", "profile", "controller"])[columns].mean()
    overall = table.groupby("controller")[columns].mean()
    overall.index = pd.MultiIndex.from_tuples(
        [("all", "all", c) for c in overall.index], names=cells.index.names
    )
    return pd.concat([cells, overall]).unstack("controller")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m pushctl.evaluation.heldout")
    parser.add_argument("--policy", required=True, type=Path)
    parser.add_argument("--per-cell", type=int, default=20)
    parser.add_argument("--plant", default="sim", choices=("sim", "proxy"))
    parser.add_argument("--out", type=Path, default=Path("results/heldout_sim.csv"))
    args = parser.parse_args(argv)
    try:
        policy = load_policy(args.policy)
        table = heldout_table(policy, args.per_cell, plant=args.plant)
    except PushctlError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    made_by = provenance_line(
        extra=f"evaluation seeds 0-{args.per_cell - 1}; policy from: {policy.made_by}"
    )
    write_csv(args.out, table, made_by)
    with pd.option_context("display.width", 200, "display.max_columns", 20):
        print(summary(table).to_string(float_format=lambda v: f"{v:.4g}"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
