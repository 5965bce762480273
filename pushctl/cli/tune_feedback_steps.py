"""``pushctl tune-feedback``: the search of :mod:`pushctl.evaluation.tune_feedback` with a
status line, its table, and the gains file's text. The command: :mod:`pushctl.cli.tune_feedback`."""

from __future__ import annotations

from pathlib import Path

from rich.console import Console
from rich.table import Table

from pushctl.control.feedback import FeedbackGains
from pushctl.errors import ConfigError
from pushctl.evaluation.tune_feedback import (
    FeedbackCandidate,
    best_feedback,
    feedback_toml,
    reset_pushes,
    score,
    tune_feedback,
    tuning_env,
)
from pushctl.files.provenance import provenance_line
from pushctl.objects import OBJECT_NAMES
from pushctl.planning import PROFILE_NAMES

TUNING_PLANTS = {"sim": ("sim",), "proxy": ("proxy",), "both": ("sim", "proxy")}
"""``--plant``: the plants whose tuning pushes the search scores (the same scenario seeds
on each)."""


def run_search(
    seed: int,
    per_case: int,
    duration: float,
    out: Path,
    command: str,
    console: Console,
    plant: str = "both",
) -> tuple[Path, str, Table]:
    """Reset the tuning set, score PD-only and the candidates; returns the file to write,
    its text and the table of the best candidates."""
    if not isinstance(seed, int) or seed < 0:
        raise ConfigError(f"--first-scenario must be an integer >= 0, got {seed!r}")
    if plant not in TUNING_PLANTS:
        raise ConfigError(f"--plant must be one of {', '.join(TUNING_PLANTS)}, got {plant!r}")
    plants = TUNING_PLANTS[plant]
    pushes = []
    with console.status("resetting the tuning pushes"):
        for kind in plants:
            plant_env = tuning_env(duration, plant=kind)
            pushes += reset_pushes(plant_env, seed, OBJECT_NAMES, PROFILE_NAMES, per_case)
    with console.status("PD-only") as status:
        pd_only = score(None, pushes)

        def show(candidate: FeedbackCandidate) -> None:
            status.update(
                f"k {candidate.k:.4g} /s, k_i {candidate.k_i:.4g} /s²: "
                f"{candidate.objective:.4f} % (PD-only {pd_only.objective:.4f} %)"
            )

        base = FeedbackGains()
        candidates = tune_feedback(pushes, base, progress=show)
    best = best_feedback(candidates)
    config = plant_env.config  # the residual settings: the same on every plant
    search: dict[str, object] = {
        "procedure": "grid then refinement (pushctl.evaluation.tune_feedback)",
        "objective": "mean over the tuning set of translation error % + angle error %",
        "stream": "tuning",
        "seed": seed,
        "per_case": per_case,
        "objects": list(OBJECT_NAMES),
        "profiles": list(PROFILE_NAMES),
        "plants": list(plants),
        "plant_ranges": "pushctl/defaults/randomisation.toml, with the plant unknowns",
        "duration": duration,
        "residual_path": config.residual_path,
        "action_scale_linear": config.action_scale_linear,
        "action_scale_angular": config.action_scale_angular,
        "gate_threshold": config.gate_threshold,
        "gate_length": config.gate_length,
        "offset_limit_linear": config.offset_limit_linear,
        "offset_limit_angular": config.offset_limit_angular,
    }
    header = provenance_line(command).removeprefix("# ")
    header += (
        "\nGains of the feedback baseline (docs/design.md §5). Regenerate with the command above."
    )
    text = feedback_toml(best, pd_only, candidates, search, header, base)
    return out, text, _table(candidates, pd_only)


def _table(candidates: list[FeedbackCandidate], pd_only: FeedbackCandidate) -> Table:
    table = Table(title=f"feedback gain search: {len(candidates)} candidates, best 10")
    for column in ("k /s", "k_i /s²", "translation %", "angle %", "objective", "gate open"):
        table.add_column(column, justify="right")
    rows = [pd_only, *sorted(candidates, key=lambda c: c.objective)[:10]]
    for candidate in rows:
        table.add_row(
            "PD-only" if candidate is pd_only else f"{candidate.k:.4g}",
            "" if candidate is pd_only else f"{candidate.k_i:.4g}",
            f"{candidate.translation_error_pct:.4f}",
            f"{candidate.angle_error_pct:.4f}",
            f"{candidate.objective:.4f}",
            f"{100 * candidate.gate_open_fraction:.1f} %",
        )
    return table
