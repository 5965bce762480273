"""The residual on PD-only, ablated (docs/learning-the-residual.md §8): which of the learner's
parts decide whether it learns on the full randomisation?

The base is ``experiments/ablation/pd-metrics.toml`` (the known-answer preset's learner on
every plant unknown: the metrics term alone, a decision every 50 ms, prior weight 0.4, actor
learning rate 3e-5, 200 episodes, 60 tuning pushes every 20 episodes). Each variant of
:data:`VARIANTS` changes one group of settings:

- the prior weight: 0 and 2 (the base's 0.4 is TD3+BC's; ``studies/prior_weight.py`` sweeps
  0.1 too, on the law);
- the observation's normalisation: the physical scales of ``pushctl.task.spaces`` replaced
  by ones (the networks see SI units: forces of order 1 N, pose errors of order 1e-3 m);
- the critic's parts: twin critics with target smoothing, 3-step returns, layer norm and the
  privileged critic, all on (the ``paper_v1`` preset's critic);
- the reward: eq. 17's force terms (weights 1, 1, 25) added to the metrics term, or the
  pose term (``experiments/ablation/pd-pose.toml``, and with the heading weighed four times
  more, ``pd-pose-heading.toml``) in its place;
- the contact hold: the policy's action dropped while a prong is off contact
  (``policy_holds_off_contact``).

``python -m studies.pd_ablation OUT [SEEDS [VARIANTS]]`` trains every variant for every seed
(default ``0,1,2`` and all), one run at a time into ``OUT/<variant>/seed-<seed>`` (a finished
run is skipped, a stopped one resumes), then prints :func:`summary`;
``python -m studies.pd_ablation summary OUT`` prints it from the runs there.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

from pushctl.rl.presets import Preset, load_preset

ROOT = Path(__file__).resolve().parents[1]
BASE = ROOT / "experiments" / "ablation" / "pd-metrics.toml"


def _ddpg(**changes: object) -> Callable[[Preset], Preset]:
    return lambda preset: replace(preset, ddpg=replace(preset.ddpg, **changes))


def _env(**changes: object) -> Callable[[Preset], Preset]:
    return lambda preset: replace(preset, env=replace(preset.env, **changes))


VARIANTS: dict[str, tuple[str, Callable[[Preset], Preset]]] = {
    "base": ("the base preset (prior 0.4, scaled inputs, plain critic, metrics term)", _ddpg()),
    "prior-0": ("prior weight 0", _ddpg(prior_weight=0.0)),
    "prior-2": ("prior weight 2", _ddpg(prior_weight=2.0)),
    "unscaled": ("observations in SI units (no normalisation)", _ddpg()),
    "critic-parts": (
        "twin critics, 3-step returns, layer norm, privileged critic",
        _ddpg(twin_critics=True, n_step=3, critic_layer_norm=True, privileged_critic=True),
    ),
    "eq17-metrics": (
        "eq. 17's force terms (1, 1, 25) plus the metrics term",
        _env(w_normal=1.0, w_tangential=1.0, w_torque=25.0),
    ),
    "hold": ("the policy held while a prong is off contact", _env(policy_holds_off_contact=True)),
    "pose": (
        "the pose term (100 /m) in place of the metrics term",
        _env(w_metrics=0.0, w_pose=100.0),
    ),
    "pose-heading": (
        "the pose term with the heading weighed 4x (gate_length 0.2 m)",
        _env(w_metrics=0.0, w_pose=100.0, gate_length=0.2),
    ),
    "pose-prior-2": (
        "the pose term in place of the metrics term, with prior weight 2 (two rows combined)",
        lambda preset: _ddpg(prior_weight=2.0)(_env(w_metrics=0.0, w_pose=100.0)(preset)),
    ),
}
"""Variant name → (what it changes, the change applied to the base preset)."""


def preset_of(variant: str, base: Path = BASE) -> Preset:
    """The base preset with ``variant``'s change."""
    return VARIANTS[variant][1](load_preset(str(base)))


@contextmanager
def _unit_scales(active: bool) -> Iterator[None]:
    """While active, the trainer builds its agent with unit observation scales (the
    ``unscaled`` variant); the scales travel with the actor's state, so validation and the
    shipped policy see what the actor was trained on."""
    import pushctl.rl.train as train_module

    if not active:
        yield
        return
    physical = train_module.scales
    train_module.scales = lambda entries: np.ones(len(entries))
    try:
        yield
    finally:
        train_module.scales = physical


def train(variant: str, seed: int, out: Path) -> None:
    """Train (or resume) ``variant`` with ``seed`` into ``out/<variant>/seed-<seed>``."""
    from pushctl.rl.train import POLICY, Trainer

    directory = Path(out) / variant / f"seed-{seed}"
    if (directory / POLICY).is_file():
        return
    preset = preset_of(variant)
    with _unit_scales(variant == "unscaled"):
        if (directory / "checkpoint.pt").is_file():
            trainer = Trainer.resume(directory)
        else:
            trainer = Trainer.start(preset, seed, directory)
        trainer.run(
            preset.train.episodes, made_by=f"# made by: python -m studies.pd_ablation {variant}"
        )


def _diff(row: pd.Series) -> str:
    return (
        f"{row['translation_diff']:+.2f} [{row['translation_diff_low']:+.2f}, "
        f"{row['translation_diff_high']:+.2f}], {row['angle_diff']:+.2f} "
        f"[{row['angle_diff_low']:+.2f}, {row['angle_diff_high']:+.2f}]"
    )


def summary(out: Path) -> pd.DataFrame:
    """One row per run under ``out``: variant, seed, episode 0's errors [%], the kept actor
    (episode, or none) with its paired difference from episode 0 (translation, angle:
    mean [95 % interval over the validation pushes], percentage points), the last actor's,
    and how many validated actors beat episode 0 on both errors' means."""
    rows = []
    for name in VARIANTS:
        for path in sorted((Path(out) / name).glob("seed-*/validation.csv")):
            table = pd.read_csv(path, comment="#")
            start, last, moved = table.iloc[0], table.iloc[-1], table.iloc[1:]
            kept = moved[moved["kept"].astype(bool)]
            better = moved[(moved["translation_diff"] < 0) & (moved["angle_diff"] < 0)]
            rows.append(
                {
                    "variant": name,
                    "seed": int(path.parent.name.removeprefix("seed-")),
                    "episode_0": (
                        f"{start['translation_error_pct']:.2f} / {start['angle_error_pct']:.2f}"
                    ),
                    "kept": (
                        f"ep {int(kept.iloc[-1]['episode'])}: {_diff(kept.iloc[-1])}"
                        if len(kept)
                        else "none"
                    ),
                    "last": f"ep {int(last['episode'])}: {_diff(last)}",
                    "better_on_both_means": f"{len(better)} of {len(moved)}",
                }
            )
    return pd.DataFrame(rows)


def main(argv: list[str]) -> None:
    if len(argv) == 2 and argv[0] == "summary":
        out = Path(argv[1])
    elif 1 <= len(argv) <= 3:
        out = Path(argv[0])
        seeds = [int(s) for s in (argv[1] if len(argv) > 1 else "0,1,2").split(",")]
        names = argv[2].split(",") if len(argv) > 2 else list(VARIANTS)
        unknown = sorted(set(names) - set(VARIANTS))
        if unknown:
            sys.exit(f"unknown variants {unknown}; known: {', '.join(VARIANTS)}")
        for name in names:
            for seed in seeds:
                train(name, seed, out)
                print(f"{name} seed {seed} done", flush=True)
    else:
        sys.exit(__doc__)
    with pd.option_context("display.width", 250, "display.max_colwidth", 80):
        print(summary(out).to_string(index=False))


if __name__ == "__main__":
    main(sys.argv[1:])
