"""The README and the docs/ pages it leads to: their structure, and their examples run as
written (the Python blocks, and the tour's first two commands). Page lengths, links and the
absence of development history are tests/test_docs.py's."""

import re
import shlex
from pathlib import Path

import pytest
from typer.testing import CliRunner

from pushctl.cli import app

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
DOCS = ROOT / "docs"


def python_blocks(path: Path) -> list[str]:
    return re.findall(r"```python\n(.*?)```", path.read_text(), flags=re.S)


def run_block(path: Path, marker: str) -> dict:
    blocks = [block for block in python_blocks(path) if marker in block]
    assert blocks, f"{path.name} has no Python example with {marker!r}"
    namespace: dict = {}
    exec(compile(blocks[0], str(path), "exec"), namespace)  # noqa: S102 - our own docs
    return namespace


def readme_section(heading: str) -> str:
    return README.read_text().split(f"\n## {heading}\n")[1].split("\n## ")[0]


def test_readme_keeps_its_sections() -> None:
    text = README.read_text()
    for heading in (
        "## The two commands",
        "## A ten-minute tour",
        "## Does it work?",
        "## Where to go next",
    ):
        assert f"\n{heading}\n" in text
    assert "| object, profile |" in readme_section("Does it work?")  # beside the paper's
    for command in ("make test", "make reproduce-tables"):
        assert command in readme_section("The two commands")


def test_gymnasium_examples_import_pushctl_before_making_the_environment() -> None:
    """``gymnasium.make("pushctl/…")`` finds the id only once ``import pushctl`` ran."""
    blocks = [
        block
        for path in [README, *sorted(DOCS.rglob("*.md"))]
        for block in python_blocks(path)
        if re.search(r"gymnasium\.make(_vec)?\(\s*\"pushctl/", block)
    ]
    assert len(blocks) >= 2
    for block in blocks:
        made = re.search(r"gymnasium\.make(_vec)?\(", block).start()
        assert re.search(r"^import pushctl\b", block[:made], flags=re.M), block


def test_the_readme_python_example_runs() -> None:
    import gymnasium

    block = next(b for b in python_blocks(README) if "gymnasium.make" in b)
    env_id = re.search(r'gymnasium\.make\("([^"]+)"', block)[1]
    import pushctl.rl  # noqa: F401 - registers them here, where pushctl came before gymnasium

    registered = {name for name in gymnasium.registry if name.startswith("pushctl/")}
    assert registered, "import pushctl registers no environment"
    if env_id not in registered:  # a tree whose newest version is not the README's yet
        pytest.skip(f"{env_id} is not registered here, only {sorted(registered)}")
    namespace: dict = {}
    exec(compile(block, str(README), "exec"), namespace)  # noqa: S102 - our own docs
    assert namespace["obs"] in namespace["env"].observation_space
    assert namespace["world"].object_pose.shape == (3,)


def test_every_figure_exists_and_names_the_command_that_made_it() -> None:
    for path in [README, *sorted(DOCS.rglob("*.md"))]:
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
    tour = readme_section("A ten-minute tour")
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

    section = readme_section("Does it work?")
    shown = [line for line in section.splitlines() if line.startswith(("| cube", "| wedge"))]
    assert shown == readme_rows(ROOT / "results")
    assert main([str(tmp_path)]) == 2
