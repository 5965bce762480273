"""What the PD baseline does on many drawn scenarios: one row per episode, metrics included.

Run as ``python -m studies.pd_sweep [--plant sim|proxy|nominal] [--seeds 8]
[--stream training] [--out results/pd_sweep_sim.csv] [--force]``; like every writing command
it refuses an existing output file unless ``--force`` (:mod:`pushctl.files.output_guard`).
Scenario i of every object × profile is seed i of the stream
(:func:`pushctl.episode.draw.draw_scenario`); the CSV records the command, and per row the
seed, goal, plant parameters and metrics. The summary printed per object × profile is the
mean of each metric and the share of episodes with more than 1 % of their steps in slip or
in contact loss (docs/design.md §6 asks for that share).
"""

from __future__ import annotations

import argparse
import itertools
import math
from pathlib import Path

import pandas as pd

from pushctl.control import PDGains, load_gains
from pushctl.episode import Episode
from pushctl.episode.draw import draw_scenario
from pushctl.episode.metrics import compute_metrics
from pushctl.planning import PROFILE_NAMES

OBJECTS = ("cube", "wedge")


def run_sweep(
    seeds: int,
    stream: str = "training",
    plant: str | None = "sim",
    gains: PDGains | None = None,
    objects: tuple[str, ...] = OBJECTS,
    profiles: tuple[str, ...] = PROFILE_NAMES,
    duration: float = 20.0,
) -> pd.DataFrame:
    """Episodes for seeds 0 … ``seeds`` − 1 of ``stream`` per object × profile; ``plant``
    None runs the nominal parameters. One row per episode."""
    gains = gains if gains is not None else load_gains()
    rows = []
    for object_name, profile, seed in itertools.product(objects, profiles, range(seeds)):
        scenario, redrawn = draw_scenario(
            seed, stream, object_name, profile, plant=plant, duration=duration
        )
        episode = Episode(scenario, gains=gains)
        metrics = compute_metrics(episode.run())
        p = episode.scenario.true_parameters
        rows.append(
            {
                "object": object_name,
                "profile": profile,
                "seed": seed,
                "goals_redrawn": redrawn,
                "goal_x": scenario.goal.x,
                "goal_y": scenario.goal.y,
                "goal_theta_deg": math.degrees(scenario.goal.theta),
                "mu_ground": p.mu_ground,
                "mu_contact": p.mu_contact,
                "object_mass": episode.object.mass,
                "pusher_mass": episode.object.pusher_mass,
                **metrics.as_dict(),
            }
        )
    return pd.DataFrame(rows)


def summary(frame: pd.DataFrame) -> pd.DataFrame:
    """Per object × profile: mean metrics and the share of episodes with > 1 % slip or loss."""
    grouped = frame.groupby(["object", "profile"], sort=False)
    table = grouped[
        ["translation_error_pct", "angle_error_pct", "force_error", "torque_error"]
        + ["contact_loss_fraction", "slip_fraction", "max_penetration"]
    ].mean()
    table["episodes_slip_over_1pct"] = grouped["slip_fraction"].apply(lambda s: (s > 0.01).mean())
    table["episodes_loss_over_1pct"] = grouped["contact_loss_fraction"].apply(
        lambda s: (s > 0.01).mean()
    )
    return table


def sweep_command(args: argparse.Namespace) -> str:
    """The sweep's provenance command: every argument's effective value except ``--out``,
    which changes no byte (the rule of ``pushctl.files.provenance.NOT_RECORDED``)."""
    return (
        f"python -m studies.pd_sweep --plant {args.plant} --seeds {args.seeds} "
        f"--stream {args.stream}"
    )


def main(argv: list[str] | None = None) -> int:
    from pushctl.errors import ConfigError
    from pushctl.files.output_guard import refuse_existing_files
    from pushctl.files.provenance import provenance_line, write_csv

    parser = argparse.ArgumentParser(
        prog="python -m studies.pd_sweep", description=__doc__.splitlines()[0]
    )
    parser.add_argument("--plant", choices=("sim", "proxy", "nominal"), default="sim")
    parser.add_argument("--seeds", type=int, default=8)
    parser.add_argument("--stream", choices=("training", "tuning"), default="training")
    parser.add_argument("--out", type=Path, default=None)
    parser.add_argument("--force", action="store_true", help="overwrite an existing --out")
    args = parser.parse_args(argv)
    if args.seeds < 1:
        parser.error("--seeds must be >= 1")
    out = args.out or Path(f"results/pd_sweep_{args.plant}.csv")
    try:
        refuse_existing_files("--out", (out,), args.force)
    except ConfigError as error:
        parser.exit(2, f"error: {error}\n")
    plant = None if args.plant == "nominal" else args.plant
    frame = run_sweep(args.seeds, args.stream, plant)
    with pd.option_context("display.width", 200, "display.max_columns", 20):
        print(summary(frame).round(4).to_string())
    out.parent.mkdir(parents=True, exist_ok=True)
    write_csv(
        out,
        frame,
        provenance_line(sweep_command(args), f"seeds 0-{args.seeds - 1} ({args.stream})"),
    )
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
