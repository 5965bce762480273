"""The code reproduces the shipped results: a short ``pushctl evaluate`` with the shipped
seed-0 policy writes, for every trial it runs, the row of the shipped
``results/evaluation/trials.csv`` to the last digit (every controller and plant). A change that
moves any last bit of a push fails here, and then ``results/`` must be made again
(docs/reproducibility.md). The shipped rows repeat on a machine of the evaluation digest's
recorded scope (numpy's AVX2 code, which pushctl pins on x86-64, and the libraries'
versions: pushctl/machine/__init__.py): elsewhere the test is skipped, saying what differs."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest
from shipped_digests import EVALUATION_ARGS, content_digest, recorded_for_this_machine
from typer.testing import CliRunner

from pushctl.cli import app

RESULTS = Path(__file__).resolve().parents[2] / "results"
KEY = ["object", "profile", "plant", "controller", "trial", "policy_seed"]


def test_a_short_evaluation_writes_the_shipped_rows(tmp_path: Path) -> None:
    recorded, why_not = recorded_for_this_machine("evaluation")
    if recorded is None:
        pytest.skip(why_not)
    out = tmp_path / "evaluation"
    policy = RESULTS / "training" / "seed-0" / "policy.pt"
    done = CliRunner().invoke(app, [*EVALUATION_ARGS, "--policy", str(policy), "--out", str(out)])
    assert done.exit_code == 0, done.output
    # every step of these pushes as recorded with the shipped code (tests/test_shipped_digests.py)
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
