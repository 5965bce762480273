"""Every command's ``--help`` in one notation: physical options name their unit, flags show
no value, defaults appear only as Typer's ``[default: …]``, and no help text loses brackets to
rich's markup. Each option name means one thing: ``--seed`` is a training run's seed."""

from __future__ import annotations

import pytest
import typer
from rich.text import Text
from typer.testing import CliRunner

from pushctl.cli import app
from pushctl.cli.common import POSE

runner = CliRunner()
TOP = typer.main.get_command(app).commands  # type: ignore[attr-defined]
COMMANDS = dict(TOP) | {
    f"{name} {sub}": command
    for name, group in TOP.items()
    if hasattr(group, "commands")
    for sub, command in group.commands.items()
}
"""Every command, a group's commands under ``group sub`` as well."""
UNITS = {"--goal": POSE, "--start": POSE, "--object-mass": "[kg]", "--duration": "[s]"}
"""Options whose placeholder must be this unit; every other number with a fraction
(``float``) must show some bracketed unit too."""


def _options(name: str):
    return [p for p in COMMANDS[name].params if p.param_type_name == "option" and not p.hidden]


def _help(name: str) -> str:
    result = runner.invoke(
        app, [*name.split(), "--help"], env={"COLUMNS": "200"}, terminal_width=200
    )
    assert result.exit_code == 0, result.output
    return result.output


def _row(text: str, option: str) -> str:
    return next(line for line in text.splitlines() if f" {option} " in line)


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_flags_show_no_value_and_physical_options_their_unit(name: str) -> None:
    text = _help(name)
    assert "<bool>" not in text
    for option in _options(name):
        flag = option.opts[0]
        if flag in UNITS:
            assert UNITS[flag] in _row(text, flag), flag
        elif option.bare_type() == "float":
            assert option.metavar and option.metavar.startswith("["), (name, flag)


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_defaults_are_shown_one_way_and_help_survives_markup(name: str) -> None:
    for option in _options(name):
        help_text = option.help or ""
        assert "default" not in help_text.lower(), (name, option.opts[0], help_text)
        assert Text.from_markup(help_text).plain == help_text.replace("\\[", "["), help_text


def test_seed_names_a_training_runs_seed_only() -> None:
    """``--seed`` is the run's seed (train); scenarios are ``--scenario`` (one),
    ``--first-scenario`` (a tuning set) and ``--scenario-block`` (an evaluation)."""
    with_seed = sorted(n for n in COMMANDS if any("--seed" in o.opts for o in _options(n)))
    assert with_seed == ["train"]
    named = {n: {o.opts[0] for o in _options(n)} for n in COMMANDS}
    assert "--scenario" in named["simulate"]
    assert "--first-scenario" in named["tune-pd"] and "--first-scenario" in named["tune-feedback"]
    assert "--scenario-block" in named["evaluate"]


def test_the_old_spelling_still_runs_under_the_new_name(tmp_path) -> None:
    result = runner.invoke(app, ["evaluate", "--seed", "-1", "--out", str(tmp_path / "e")])
    assert result.exit_code == 2
    assert "note: --seed is now --scenario-block" in result.output
    assert "--scenario-block must be an integer >= 0, got -1" in result.output
