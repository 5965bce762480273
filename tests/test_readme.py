"""The README and the docs/ pages it leads to: short, complete, and their examples run as
written (the Python blocks, and the tour's first two commands)."""

import re
import shlex
from pathlib import Path

import pytest
from typer.testing import CliRunner

from pushctl.cli import app

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
DOCS = ROOT / "docs"
OWN_PAGES = (
    "design.md",
    "glossary.md",
    "model.md",
    "validation.md",
    "planning.md",
    "control.md",
    "learning.md",
    "evaluation.md",
    "results.md",
    "reproducibility.md",
    "benchmarks.md",
    "kinova-facts.md",
    "mujoco.md",
    "plant-unknowns.md",
    "ray.md",
    "several-seeds.md",
    "residual-and-feedback.md",
    "reproducibility-and-speed.md",
)


def python_blocks(path: Path) -> list[str]:
    return re.findall(r"```python\n(.*?)```", path.read_text(), flags=re.S)


def run_block(path: Path, marker: str) -> dict:
    blocks = [block for block in python_blocks(path) if marker in block]
    assert blocks, f"{path.name} has no Python example with {marker!r}"
    namespace: dict = {}
    exec(compile(blocks[0], str(path), "exec"), namespace)  # noqa: S102 - our own docs
    return namespace


def test_readme_is_short_and_keeps_its_results_section() -> None:
    text = README.read_text()
    assert len(text.splitlines()) <= 300
    section = text.split("\n## Does it work?\n")[1].split("\n## ")[0]
    assert "| object, profile |" in section  # the results table beside the paper's
    for heading in ("## The two commands", "## A ten-minute tour", "## Where to go next"):
        assert f"\n{heading}\n" in text
    for command in ("make test", "make reproduce-tables"):
        assert command in text.split("\n## The two commands\n")[1].split("\n## ")[0]


def test_readme_links_every_docs_page() -> None:
    text = README.read_text()
    for page in sorted(DOCS.glob("*.md")):
        assert f"](docs/{page.name})" in text, f"the README does not link docs/{page.name}"


def test_every_page_starts_with_what_it_answers() -> None:
    for name in OWN_PAGES:
        lines = (DOCS / name).read_text().splitlines()
        assert lines[0].startswith("# "), name
        assert any("This page answers" in line for line in lines[:6]), name


def test_every_figure_exists_and_names_the_command_that_made_it() -> None:
    for path in [README, *sorted(DOCS.glob("*.md"))]:
        text = path.read_text()
        for match in re.finditer(r"!\[(?P<alt>[^\]]*)\]\((?P<target>[^)]+)\)", text):
            target = (path.parent / match["target"]).resolve()
            assert target.is_file(), f"{path.name}: {match['target']} does not exist"
            after = text[match.end() : match.end() + 400]
            made_by = match["alt"] + after.split("\n\n![")[0]
            assert "pushctl " in made_by or "make " in made_by, (
                f"{path.name}: the figure {match['target']} names no command"
            )


def test_the_world_example_runs() -> None:
    namespace = run_block(DOCS / "model.md", "solve_box_mlcp")
    assert namespace["sol"].converged
    assert abs(namespace["table"].object_pose[0] - 0.5**2 / (2 * 0.3 * 9.81)) < 1e-3


def test_the_planning_example_runs() -> None:
    plan = run_block(DOCS / "planning.md", "make_plan")["plan"]
    assert plan.feasible and plan.problems == ()
    assert plan.forces.forces.shape == (2001, 2, 2)


def test_the_episode_example_runs() -> None:
    namespace = run_block(DOCS / "control.md", "Episode(")
    metrics = namespace["metrics"]
    assert namespace["trace"].n_steps == 2000
    assert metrics.translation_error_pct < 1.0 and metrics.max_penetration < 1e-3


def tour_command(name: str) -> list[str]:
    """The README tour's ``pushctl NAME …`` command line, as arguments."""
    tour = README.read_text().split("\n## A ten-minute tour\n")[1].split("\n## ")[0]
    lines = [line for line in tour.splitlines() if line.startswith(f"pushctl {name} ")]
    assert len(lines) == 1, f"the tour has no single `pushctl {name}` command"
    return shlex.split(lines[0])[1:]


@pytest.mark.parametrize("name", ["plan", "simulate"])
def test_the_tour_commands_run_as_written(
    name: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Run in an empty folder, so the outputs the README names land there."""
    monkeypatch.chdir(tmp_path)
    arguments = tour_command(name)
    result = CliRunner().invoke(app, arguments)
    assert result.exit_code == 0, result.output
    outputs = [arguments[i + 1] for i, a in enumerate(arguments) if a in ("--out", "--plot")]
    assert outputs and all((tmp_path / output).stat().st_size > 0 for output in outputs)


def test_the_tour_evaluates_and_reports_with_real_options() -> None:
    """The two slower tour commands name options their commands accept (their runs are
    tested in tests/evaluation/test_evaluate.py and tests/cli/test_cli_report.py)."""
    for name in ("evaluate", "report"):
        arguments = tour_command(name)
        help_text = CliRunner().invoke(app, [name, "--help"]).output
        for option in (a for a in arguments if a.startswith("--")):
            assert option in help_text, f"pushctl {name} has no {option}"


def test_readme_table_is_the_shipped_results(tmp_path: Path) -> None:
    """The *Does it work?* table shows the committed `results/` as
    `python -m studies.readme_table results` renders them, so a regenerated run
    that leaves the README behind fails here; a missing table is a one-line error."""
    from studies.readme_table import main, readme_rows

    section = README.read_text().split("\n## Does it work?\n")[1].split("\n## ")[0]
    shown = [line for line in section.splitlines() if line.startswith(("| cube", "| wedge"))]
    assert shown == readme_rows(ROOT / "results")
    assert main([str(tmp_path)]) == 2
