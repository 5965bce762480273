"""Which actor a policy file holds, in one line for ``train`` and ``evaluate``.

Training ships, when its preset validates, the best actor that beat PD-only and was no
worse than episode 0's zero residual on the validation set; when none did, it ships that
zero residual under the run's settings: on a base law the law itself, else the PD baseline
(re-landed when the run re-lands) (:mod:`pushctl.rl.train`). A
zero residual is an actor whose output layer is all zeros, so the file alone tells which
case it is; the run's ``validation.csv``, when it is at hand, tells which episode's actor a
trained one is.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import torch

from pushctl.rl.policy import TrainedPolicy
from pushctl.rl.train import POLICY, VALIDATION

LAW_NAMES = {"feedback": "the feedback law (PD + PI on the pose)"}


def is_zero_residual(policy: TrainedPolicy) -> bool:
    """True if the actor outputs 0 for every observation: its last layer is all zeros."""
    last = [m for m in policy.actor.actor.net if isinstance(m, torch.nn.Linear)][-1]
    return not (last.weight.any() or last.bias.any())


def describe_policy(policy: TrainedPolicy, validation: pd.DataFrame | None = None) -> str:
    """One line: the law or PD-only (a zero residual), else the trained residual, naming the
    episode it was kept at when ``validation`` (the run's ``validation.csv``) is given."""
    law = policy.env.base_law
    if is_zero_residual(policy):
        if law != "none":
            return f"no actor beat the law: this policy is the law, {LAW_NAMES.get(law, law)}"
        landed = ", re-landed" if policy.env.landing == "measured" else ""
        return f"no actor beat the zero residual: this policy is PD-only{landed}"
    base = f"on {LAW_NAMES.get(law, law)}" if law != "none" else "on PD"
    kept = _kept_row(validation)
    if kept is None:
        return f"a trained residual {base}"
    return (
        f"a trained residual {base}: the actor of episode {int(kept['episode'])} "
        f"({int(kept['updates'])} updates), the best on the validation set"
    )


def _kept_row(validation: pd.DataFrame | None) -> pd.Series | None:
    """The row of the actor training kept last (the lowest score of the kept ones)."""
    if validation is None or "kept" not in validation or not validation["kept"].any():
        return None
    kept = validation[validation["kept"].astype(bool)]
    return kept.loc[kept["score"].idxmin()]


def read_validation(policy_path: Path) -> pd.DataFrame | None:
    """The ``validation.csv`` beside a run's chosen ``policy.pt`` (None for another file
    name, such as ``policy_last.pt``, or if it is missing or unreadable)."""
    path = Path(policy_path)
    if path.name != POLICY:
        return None
    try:
        return pd.read_csv(path.with_name(VALIDATION), comment="#")
    except (OSError, ValueError):
        return None
