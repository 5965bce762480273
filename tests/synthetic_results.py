"""Synthetic results CSVs with known means (trials.csv, steps.csv, curve.csv), shared by the
report's tests (tests/report/) and the command line's (tests/cli/): a module, not a test
file, so every test directory can import it (tests/ is on sys.path through conftest.py)."""

from __future__ import annotations

import hashlib
import itertools
import math
from pathlib import Path

import numpy as np
import pandas as pd

OBJECTS = ("cube", "wedge")
PROFILES = ("constant", "trapezoid", "chirp")
TRIALS = 4
STEPS = 10
GROUPS = list(itertools.product(OBJECTS, PROFILES, ("sim", "proxy"), ("pd", "feedback", "rl")))
"""Every (object, profile, plant, controller) of the synthetic inputs, in file order."""
EPISODES = 40
PD_EVERY = 4
TRIALS_MADE_BY = "# made by: pushctl evaluate --trials 4; pushctl 0.1.0; commit abc1234; seed 7"

# Hand computation for the values 1, 2, 3, 4 (× a factor f): mean 2.5 f, sample standard
# deviation √(5/3) f = 1.2909944 f, t(0.975, 3) = 3.1824463, half-width t·s/√4 = 2.0542799 f.
CI_1234 = 3.1824463053 * math.sqrt(5.0 / 3.0) / 2.0
# With the first value NaN: 2, 3, 4, mean 3 f, s = f, t(0.975, 2) = 4.3026527, half-width
# t·s/√3 = 2.4841377 f.
CI_234 = 4.3026527297 / math.sqrt(3.0)


def sign(path: Path) -> None:
    """End ``path`` (a CSV) in the digest of its bytes, as pushctl writes it, replacing the
    digest line it may already end in."""
    from pushctl.files.provenance import DIGEST_PREFIX

    lines = path.read_text().splitlines(keepends=True)
    data = "".join(line for line in lines if not line.startswith(DIGEST_PREFIX)).encode()
    path.write_bytes(data + f"{DIGEST_PREFIX}{hashlib.sha256(data).hexdigest()}\n".encode())


def factor(plant: str, controller: str) -> float:
    """The synthetic metrics are (trial + 1) × this: RL half of PD and 0.8 of feedback,
    proxy 1.5 × sim."""
    scale = {"pd": 2.0, "feedback": 1.25, "rl": 1.0}[controller]
    return scale * (1.5 if plant == "proxy" else 1.0)


def trials_frame() -> pd.DataFrame:
    """trials.csv rows: every object × profile × plant × controller × 4 trials, the metrics
    (trial + 1) × factor; cube/constant/pd's first angle error NaN (a straight push)."""
    rows = []
    for obj, profile, plant, controller in GROUPS:
        f = factor(plant, controller)
        for trial in range(TRIALS):
            value = (trial + 1) * f
            straight = (obj, profile, controller, trial) == ("cube", "constant", "pd", 0)
            rows.append(
                {
                    "object": obj,
                    "profile": profile,
                    "plant": plant,
                    "controller": controller,
                    "trial": trial,
                    "seed": 100 + trial,
                    "translation_error_pct": value,
                    "angle_error_pct": math.nan if straight else value / 10,
                    "force_error": value * 1e-3,
                    "force_error_landed": value * 0.5e-3,
                    "torque_error": value * 1e-5,
                    "slip_fraction": value / 100,
                }
            )
    return pd.DataFrame(rows)


def steps_frame() -> pd.DataFrame:
    """steps.csv rows: 11 steps of 0.1 s per group; PD lags the plan by 2 mm, RL by 1 mm."""
    rows = []
    for obj, profile, plant, controller in GROUPS:
        lag = factor(plant, controller)
        for step in range(STEPS + 1):
            des = 15.0 * step
            rows.append(
                {
                    "object": obj,
                    "profile": profile,
                    "plant": plant,
                    "controller": controller,
                    "step": step,
                    "t": 0.1 * step,
                    "translation_des_mm": des,
                    "translation_mm": des - lag,
                    "angle_des_deg": 3.0 * step,
                    "angle_deg": 3.0 * step - 0.1 * lag,
                    "translation_error_mm": lag,
                    "angle_error_deg": 0.1 * lag,
                    "force_error": 1e-3 * lag if step else math.nan,
                    "torque_error": 1e-5 * lag if step else math.nan,
                }
            )
    return pd.DataFrame(rows)


def curve_frame() -> pd.DataFrame:
    """curve.csv rows: 40 episodes; PD-only on every 4th (empty elsewhere)."""
    episode = np.arange(EPISODES)
    frame = pd.DataFrame({"episode": episode, "object": "cube", "profile": "chirp"})
    for metric, scale in (("force_n_error", 1e-2), ("force_t_error", 5e-3), ("torque_error", 1e-4)):
        frame[f"rl_{metric}"] = scale * (1.0 + np.exp(-episode / 10.0))
        frame[f"pd_{metric}"] = np.where(episode % PD_EVERY == 0, 2.0 * scale, np.nan)
    return frame


def write_results(root: Path) -> Path:
    """Write the three synthetic inputs under ``root`` (trials.csv with a provenance line
    and its digest, as pushctl writes it; the others without either, as if made by hand);
    returns ``root``."""
    (root / "evaluation").mkdir(parents=True)
    (root / "training").mkdir(parents=True)
    with (root / "evaluation" / "trials.csv").open("w") as handle:
        handle.write(TRIALS_MADE_BY + "\n")
        trials_frame().to_csv(handle, index=False)
    sign(root / "evaluation" / "trials.csv")
    steps_frame().to_csv(root / "evaluation" / "steps.csv", index=False)
    curve_frame().to_csv(root / "training" / "curve.csv", index=False)
    return root
