"""``pushctl report`` end to end on small synthetic results: every output written with its
provenance, the tables readable back, and bad input (a missing directory, an empty file, a
missing column, garbage) rejected with one line and exit code 2, writing nothing."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest
from PIL import Image
from synthetic_results import write_results
from typer.testing import CliRunner

from pushctl.cli import app
from pushctl.cli.report_steps import write_chain
from pushctl.errors import WriteError

runner = CliRunner()
OUTPUTS = (
    "table3.csv",
    "table3_proxy.csv",
    "behaviour.csv",
    "table4.csv",
    "tables.md",
    "fig5_training.png",
    "fig6_tracking.png",
    "fig8_force_error.png",
)


@pytest.fixture(scope="module")
def report_run(tmp_path_factory) -> tuple[Path, Path, str]:
    """One run of the command on the synthetic results (figures take a few seconds)."""
    root = tmp_path_factory.mktemp("report")
    results = write_results(root / "results")
    out = root / "out"
    result = runner.invoke(app, ["report", "--in", str(results), "--out", str(out)])
    assert result.exit_code == 0, result.output
    return results, out, result.output


def test_report_writes_every_output(report_run):
    _, out, output = report_run
    assert sorted(p.name for p in out.iterdir()) == sorted(OUTPUTS)
    for name in OUTPUTS:
        assert f"{out / name}" in output.replace("\n", "")


def test_tables_carry_provenance_naming_their_input(report_run):
    results, out, _ = report_run
    first = (out / "table3.csv").read_text().splitlines()[0]
    assert first.startswith("# made by: pushctl report --in")
    assert f"{results / 'evaluation' / 'trials.csv'} [" in first
    # the input's own line, its pushctl version left out
    assert "[pushctl evaluate --trials 4; commit abc1234; seed 7]" in first
    table = pd.read_csv(out / "table3.csv", comment="#")
    assert list(table.columns[:8]) == [
        "object",
        "profile",
        "translation_error_pd",
        "translation_error_feedback",
        "translation_error_rl",
        "angle_error_pd",
        "angle_error_feedback",
        "angle_error_rl",
    ]
    assert len(table) == 6
    row = table[(table["object"] == "wedge") & (table["profile"] == "chirp")].iloc[0]
    assert row["translation_error_pd"] == pytest.approx(5.0)
    four = pd.read_csv(out / "table4.csv", comment="#")
    assert four["force_error_rl_proxy"].iloc[0] == pytest.approx(3.75e-3)
    assert four.columns[-1] == "torque_error_rl_proxy_ci95"


def test_markdown_and_figures_carry_provenance(report_run):
    results, out, _ = report_run
    text = (out / "tables.md").read_text()
    assert text.startswith("<!-- made by: pushctl report --in")
    assert "22.3" in text and "| 171 |" in text
    assert f"{results / 'training' / 'curve.csv'} [no provenance line]" in text
    for name, fig in (("fig5_training.png", "Fig. 5"), ("fig8_force_error.png", "Fig. 8")):
        with Image.open(out / name) as image:
            description = image.info["Description"]
            assert image.size[0] > 1000
        assert description.startswith(fig) and "made by: pushctl report" in description
    with Image.open(out / "fig6_tracking.png") as image:
        assert "evaluation/steps.csv" in image.info["Description"]


def _break(results: Path, kind: str) -> Path:
    """Damage ``results`` one way; returns the --in directory to use."""
    trials = results / "evaluation" / "trials.csv"
    if kind == "missing-dir":
        return results / "nope"
    if kind == "empty-file":
        trials.write_text("")
    elif kind == "missing-column":
        frame = pd.read_csv(trials, comment="#").drop(columns="angle_error_pct")
        frame.to_csv(trials, index=False)
    elif kind == "garbage":
        (results / "training" / "curve.csv").write_bytes(b"\x89PNG\r\n\x1a\n\x00\xff\xfe garbage")
    elif kind == "missing-steps":
        (results / "evaluation" / "steps.csv").unlink()
    return results


@pytest.mark.parametrize(
    ("kind", "fragment"),
    [
        ("missing-dir", "nope: no such directory"),
        ("empty-file", "trials.csv: empty file"),
        ("missing-column", "trials.csv: missing column(s) angle_error_pct"),
        ("garbage", "curve.csv: not a"),
        ("missing-steps", "steps.csv: no such file"),
    ],
)
def test_bad_input_gives_one_line_exit_2_and_writes_nothing(tmp_path, kind, fragment):
    results = write_results(tmp_path / "results")
    in_dir = _break(results, kind)
    out = tmp_path / "out"
    out.mkdir()
    (out / "table3.csv").write_text("old\n")  # an earlier report's file stays as it was
    args = ["report", "--in", str(in_dir), "--out", str(out), "--force"]
    result = runner.invoke(app, args)
    assert result.exit_code == 2, result.output
    assert fragment in result.output
    assert "Traceback" not in result.output
    assert len(result.output.strip().splitlines()) == 1
    assert [p.name for p in out.iterdir()] == ["table3.csv"]
    assert (out / "table3.csv").read_text() == "old\n"


def test_out_that_is_a_file_is_refused(tmp_path):
    results = write_results(tmp_path / "results")
    target = tmp_path / "file.txt"
    target.write_text("keep")
    result = runner.invoke(app, ["report", "--in", str(results), "--out", str(target)])
    assert result.exit_code == 2
    assert "is a file" in result.output and len(result.output.strip().splitlines()) == 1
    assert target.read_text() == "keep"


def test_a_failed_write_renames_no_file(tmp_path):
    """write_chain: each file is renamed only after every later one was written, so a
    failure while writing the last leaves the earlier files untouched."""
    from pushctl.files.provenance import write_atomic

    first, second = tmp_path / "a.txt", tmp_path / "b.txt"
    first.write_text("old")

    def write_first(then):
        def write(tmp: Path) -> None:
            tmp.write_text("new")
            then()

        write_atomic(first, write)

    def fail(then):
        def write(tmp: Path) -> None:
            raise OSError(28, "No space left on device", str(second))

        write_atomic(second, write)

    with pytest.raises(WriteError):
        write_chain([write_first, fail])
    assert first.read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.txt"]


def test_the_docs_name_every_output_and_table_column():
    from pushctl.report.tables import TABLE3_COLUMNS

    page = (Path(__file__).resolve().parents[2] / "docs" / "evaluation.md").read_text()
    section = page.split("## Tables and figures: `pushctl report`")[1].split("\n## ")[0]
    for name in OUTPUTS:
        assert f"`{name}`" in section
    # the tables' columns, the feedback controller's included: the results-files reference
    docs = Path(__file__).resolve().parents[2] / "docs" / "reference" / "results-files.md"
    text = docs.read_text()
    for column in TABLE3_COLUMNS:
        stem, _, controller = column.rpartition("_")
        assert controller in ("pd", "feedback", "rl") and f"`{stem}_{{pd,feedback,rl}}`" in text
    for pattern in ("`force_error_*`", "`{pd,feedback,rl}_{sim,proxy}`", "`_ci95`", "`_seed_sd`"):
        assert pattern in text


def test_the_proxy_table_and_the_behaviour_table_hold_their_plants_means(report_run):
    results, out, _ = report_run
    trials = pd.read_csv(results / "evaluation" / "trials.csv", comment="#")
    proxy = pd.read_csv(out / "table3_proxy.csv", comment="#").set_index(["object", "profile"])
    behaviour = pd.read_csv(out / "behaviour.csv", comment="#").set_index(["object", "profile"])
    for (obj, profile), row in proxy.iterrows():
        cell = trials[(trials["object"] == obj) & (trials["profile"] == profile)]
        pd_proxy = cell[(cell["plant"] == "proxy") & (cell["controller"] == "pd")]
        assert row["translation_error_pd"] == pytest.approx(
            pd_proxy["translation_error_pct"].mean(), rel=1e-6
        )
        pd_sim = cell[(cell["plant"] == "sim") & (cell["controller"] == "pd")]
        assert behaviour.loc[(obj, profile), "slip_fraction_pd_sim"] == pytest.approx(
            pd_sim["slip_fraction"].mean(), rel=1e-6
        )
    assert "gate_open_fraction_pd_sim" not in behaviour.columns
    assert "gate_open_fraction_rl_proxy" in behaviour.columns


def test_a_gzipped_steps_file_is_read_as_the_plain_one(report_run, tmp_path):
    import gzip
    import shutil

    results, out, _ = report_run
    packed = tmp_path / "results"
    shutil.copytree(results, packed)
    steps = packed / "evaluation" / "steps.csv"
    with steps.open("rb") as plain, gzip.open(f"{steps}.gz", "wb") as zipped:
        shutil.copyfileobj(plain, zipped)
    steps.unlink()
    result = runner.invoke(app, ["report", "--in", str(packed), "--out", str(tmp_path / "o")])
    assert result.exit_code == 0, result.output
    for name in ("table3.csv", "table4.csv"):
        ours = (tmp_path / "o" / name).read_text().splitlines()[1:-1]  # made-by, digest differ
        assert ours == (out / name).read_text().splitlines()[1:-1]


@pytest.mark.parametrize("layout", ["results-without-training", "evaluation-directory"])
def test_an_evaluation_alone_is_reported_without_fig5(tmp_path, monkeypatch, layout):
    """No training run beside the evaluation: everything else is written, Fig. 5 is skipped
    with a note; the defaults read ``runs/`` and write ``runs/report/``."""
    results = write_results(tmp_path / "runs")
    (results / "training" / "curve.csv").unlink()
    (results / "training").rmdir()
    monkeypatch.chdir(tmp_path)
    given = [] if layout == "results-without-training" else ["--in", "runs/evaluation"]
    args = ["report", *given]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    written = sorted(p.name for p in (tmp_path / "runs" / "report").iterdir())
    assert written == sorted(set(OUTPUTS) - {"fig5_training.png"})
    assert "note: no training/curve.csv in" in result.output
    assert "Fig. 5 (training curves) not drawn" in result.output.replace("\n", " ")
