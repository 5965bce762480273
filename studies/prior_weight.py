"""The prior weight swept (docs/learning-the-residual.md): DDPG's actor loss is
−Q / mean|Q| + w·‖π(s) − π₀(s)‖² (``[ddpg] prior_weight``), π₀ the zero residual. The presets
use w = 2; TD3+BC's default (α = 2.5 on −α·Q / mean|Q| + ‖π − a‖²) is the same loss at
w = 1/α = 0.4, so the presets hold the actor five times as close to the law.

Each weight of :data:`WEIGHTS` trains the ablation ``baseline`` preset
(``experiments/ablation/baseline.toml``: the ``quick`` preset validated on 120 tuning-stream
pushes, episode 0's zero residual and the last actor, with the paired test) with that weight
only, one run after the other, into ``OUT/w-<weight>/seed-<seed>``; the table is the last
actor's validation row of each run beside episode 0's (:func:`summary`).

``python -m studies.prior_weight SEED OUT [EPISODES [PER_CELL]]`` runs the sweep (EPISODES:
the preset's 120 by default; PER_CELL: validation pushes per object × profile, the preset's
20) and prints the table; ``python -m studies.prior_weight summary OUT`` prints it from the
runs there.
"""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import pandas as pd

from pushctl.rl.presets import Preset, load_preset

ROOT = Path(__file__).resolve().parents[1]
BASELINE = ROOT / "experiments" / "ablation" / "baseline.toml"
WEIGHTS = (0.0, 0.1, 0.4, 2.0)
"""The weights swept: plain DDPG's −Q (normalised), a tenth of TD3+BC's hold, TD3+BC's, and
the presets'."""

COLUMNS = (
    "translation_error_pct",
    "angle_error_pct",
    "force_error",
    "translation_diff",
    "translation_diff_high",
    "angle_diff",
    "angle_diff_high",
    "failed",
    "law_failed",
    "kept",
)
"""The columns of ``validation.csv`` the table keeps (the paired ones: RL − episode 0)."""


def sweep_presets(
    weights: tuple[float, ...] = WEIGHTS,
    episodes: int | None = None,
    per_cell: int | None = None,
    base: Path = BASELINE,
) -> dict[float, Preset]:
    """The ``base`` preset with each of ``weights`` as ``prior_weight`` (and ``episodes``,
    ``per_cell`` validation pushes per cell, when given; the last actor is validated at the
    end of the run either way)."""
    preset = load_preset(str(base))
    train = preset.train
    if episodes is not None:
        train = replace(train, episodes=episodes, validate_every=episodes)
    if per_cell is not None:
        train = replace(train, validation_per_cell=per_cell)
    return {
        w: replace(preset, train=train, ddpg=replace(preset.ddpg, prior_weight=w)) for w in weights
    }


def run_directory(out: Path, weight: float, seed: int) -> Path:
    return Path(out) / f"w-{weight:g}" / f"seed-{seed}"


def summary(out: Path) -> pd.DataFrame:
    """One row per run under ``out``: weight, seed, the last actor's validation columns
    (:data:`COLUMNS`) and episode 0's translation, angle and force errors (``law_*``)."""
    rows = []
    for path in sorted(Path(out).glob("w-*/seed-*/validation.csv")):
        table = pd.read_csv(path, comment="#")
        start, last = table.iloc[0], table.iloc[-1]
        row = {"weight": float(path.parts[-3][2:]), "seed": int(path.parts[-2][5:])}
        row["episode"] = int(last["episode"])
        row.update({name: last[name] for name in COLUMNS if name in table})
        for name in ("translation_error_pct", "angle_error_pct", "force_error"):
            row[f"law_{name}"] = start[name]
        rows.append(row)
    return pd.DataFrame(rows).sort_values(["weight", "seed"]).reset_index(drop=True)


def sweep(seed: int, out: Path, episodes: int | None = None, per_cell: int | None = None) -> None:
    """Train every weight's preset with ``seed``, one run at a time."""
    from pushctl.rl.train import Trainer

    for weight, preset in sweep_presets(episodes=episodes, per_cell=per_cell).items():
        directory = run_directory(out, weight, seed)
        if (directory / "validation.csv").is_file():
            continue  # done before
        trainer = Trainer.start(preset, seed, directory)
        trainer.run(preset.train.episodes, made_by=f"# made by: studies.prior_weight w={weight}")


if __name__ == "__main__":
    args = sys.argv[1:]
    if len(args) == 2 and args[0] == "summary":
        print(summary(Path(args[1])).to_string(index=False))
    elif 2 <= len(args) <= 4:
        numbers = [int(a) for a in args[2:]] + [None] * (4 - len(args))
        sweep(int(args[0]), Path(args[1]), *numbers)
        print(summary(Path(args[1])).to_string(index=False))
    else:
        sys.exit(__doc__)
