"""What a first hour with pushctl meets: its version, a help without stray placeholders,
docs that use today's option names, errors in words rather than Python reprs."""

from __future__ import annotations

import re
from pathlib import Path

import torch
from typer.testing import CliRunner

from pushctl.cli import app
from pushctl.version import VERSION

ROOT = Path(__file__).resolve().parents[2]
runner = CliRunner()


def test_version_and_help():
    shown = runner.invoke(app, ["--version"])
    assert shown.exit_code == 0 and shown.output.strip() == f"pushctl {VERSION}"
    helped = runner.invoke(app, ["--help"])
    assert helped.exit_code == 0 and "<bool>" not in helped.output


def test_the_docs_use_the_scenario_options_not_their_old_spelling():
    old = re.compile(r"pushctl (simulate|evaluate|tune-pd|tune-feedback)\b[^`\n]*--seed\b")
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
    found = [f"{p.name}: {m.group(0)}" for p in pages for m in old.finditer(p.read_text())]
    assert found == []
    assert "`steps.csv.gz` (per-step means)" not in (ROOT / "README.md").read_text()


def test_a_missing_entry_is_named_in_words(tmp_path):
    policy = tmp_path / "p.pt"
    torch.save({"format": 1, "env": {}, "made_by": ""}, policy)
    args = ["evaluate", "--controller", "rl", "--trials", "1", "--object", "cube",
            "--profile", "chirp", "--plant", "sim", "--policy", str(policy),
            "--trust-undigested", "--out", str(tmp_path / "e")]  # fmt: skip
    result = runner.invoke(app, args)
    assert result.exit_code == 2 and "no actor entry" in result.stderr, result.stderr
    fit = tmp_path / "fit.toml"
    fit.write_text("[settings]\n")
    score = ["realdata", "score", "--data", str(tmp_path), "--friction", str(fit),
             "--out", str(tmp_path / "s")]  # fmt: skip
    result = runner.invoke(app, score)
    assert result.exit_code == 2 and "(no surface)" in result.stderr, result.stderr
    for shown in (result.stderr,):
        assert "KeyError" not in shown and "('" not in shown


def test_compiling_the_kernels_says_each_step_and_its_time():
    from pushctl.cli.warm import STEPS, warm

    lines: list[str] = []
    warm(report=lines.append)  # cached already in a test run: seconds
    assert [line.split(":")[0] for line in lines[:-1]] == [
        f"step {k} of {STEPS}" for k in range(1, STEPS + 1)
    ]
    assert all(re.search(r"\(\d+ min \d\d s\)$", line) for line in lines[:-1])
    assert lines[-1].startswith("kernels compiled in ")


def _results_with_runs(root: Path, evaluated: str, trained: str) -> Path:
    """Synthetic results whose trials evaluated the policy of run ``evaluated`` and whose
    curve is run ``trained``'s."""
    from synthetic_results import sign, write_results

    write_results(root)
    trials = root / "evaluation" / "trials.csv"
    lines = trials.read_text().splitlines(keepends=True)
    lines[0] = lines[0].rstrip("\n") + f"; policy p.pt, made by: {evaluated}\n"
    trials.write_text("".join(lines))
    sign(trials)
    curve = root / "training" / "curve.csv"
    curve.write_text(f"# made by: {trained}\n" + curve.read_text())
    sign(curve)
    return root


def test_a_report_says_loudly_when_fig5_is_another_runs(tmp_path):
    mine = "pushctl train --preset quick; pushctl 0.1.0; commit abc; seed 0 (training stream)"
    shipped = "pushctl train --preset experiments/train_paper_v1.toml; seed 0 (training stream)"
    mixed = _results_with_runs(tmp_path / "mixed", shipped, mine)
    result = runner.invoke(app, ["report", "--in", str(mixed), "--out", str(tmp_path / "a")])
    assert result.exit_code == 0, result.output
    warning = " ".join(result.stderr.split())
    assert warning.startswith("warning: Fig. 5 shows the training run of") and "another" in warning
    same = _results_with_runs(tmp_path / "same", mine, mine)
    result = runner.invoke(app, ["report", "--in", str(same), "--out", str(tmp_path / "b")])
    assert result.exit_code == 0 and "warning" not in result.stderr, result.stderr
