"""The code reproduces the shipped results: a short ``pushctl evaluate`` with the shipped
seed-0 policy writes, for every trial it runs, the row of the shipped
``results/evaluation/trials.csv`` to the last digit (every controller and plant). A change that
moves any last bit of a push fails here, and then ``results/`` must be made again
(docs/reproducibility.md). The shipped rows were made with numpy's AVX2 code (OpenBLAS's
Haswell kernels), which pushctl pins on x86-64 (pushctl/machine.py): elsewhere the test is
skipped."""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd
import pytest
from shipped_digests import EVALUATION_ARGS, MANIFEST, content_digest
from typer.testing import CliRunner

from pushctl.cli import app
from pushctl.machine import PINNED_KERNELS, blas_kernels

RESULTS = Path(__file__).resolve().parents[2] / "results"
KEY = ["object", "profile", "plant", "controller", "trial", "policy_seed"]


@pytest.mark.skipif(blas_kernels() != PINNED_KERNELS, reason="not the shipped kernels")
def test_a_short_evaluation_writes_the_shipped_rows(tmp_path: Path) -> None:
    out = tmp_path / "evaluation"
    policy = RESULTS / "training" / "seed-0" / "policy.pt"
    done = CliRunner().invoke(app, [*EVALUATION_ARGS, "--policy", str(policy), "--out", str(out)])
    assert done.exit_code == 0, done.output
    # every step of these pushes as recorded with the shipped code (tests/test_shipped_digests.py)
    recorded = json.loads(MANIFEST.read_text())["evaluation"]
    assert content_digest(out / "trials.csv", out / "steps.csv") == recorded
    # as text: a row equal in every printed digit
    ours = pd.read_csv(out / "trials.csv", comment="#", dtype=str, keep_default_na=False)
    shipped = pd.read_csv(
        RESULTS / "evaluation" / "trials.csv", comment="#", dtype=str, keep_default_na=False
    )
    shipped = shipped[shipped["policy_seed"].isin(["", "0"])]
    assert list(ours.columns) == list(shipped.columns)
    joined = ours.merge(shipped, on=KEY, how="left", suffixes=("", "_shipped"), indicator=True)
    assert len(joined) == len(ours) >= 12 and (joined["_merge"] == "both").all()
    assert set(ours["controller"]) >= {"pd", "rl"} and set(ours["plant"]) >= {"sim", "proxy"}
    differing = [c for c in ours.columns if c not in KEY
                 and not (joined[c] == joined[f"{c}_shipped"]).all()]  # fmt: skip
    assert differing == []
