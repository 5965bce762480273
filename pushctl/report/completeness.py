"""A trials file holds every row its provenance line names.

``pushctl evaluate`` heads ``trials.csv`` with its command line, every option's effective
value included (``--object all --profile all --trials 50 --controller all --plant all``, one
``--policy`` per training seed). That names the cells (object × profile × plant × controller)
and the trials of each, so a file cut short, even at a line boundary, is caught: a cell with
fewer rows than the line names is refused in one line. An option the line does not name, or
names with a value this check does not expand (a TOML object file), is taken from the rows.
"""

from __future__ import annotations

import itertools
import shlex

import pandas as pd

from pushctl.controllers import controller_entry, paper_controllers
from pushctl.errors import ConfigError, DamagedFileError

ALL_OBJECTS = ("cube", "wedge")
ALL_PROFILES = ("constant", "trapezoid", "chirp")
ALL_PLANTS = ("sim", "proxy", "mujoco")
BOTH_PLANTS = ("sim", "proxy")
_DIMENSIONS = (
    ("object", "--object", {"all": ALL_OBJECTS}),
    ("profile", "--profile", {"all": ALL_PROFILES}),
    ("plant", "--plant", {"all": ALL_PLANTS, "both": BOTH_PLANTS}),
    ("controller", "--controller", {"all": paper_controllers}),  # read when checking
)


def named_options(made_by: str | None) -> dict[str, list[str]]:
    """The options of an ``evaluate`` provenance line (``made by: pushctl evaluate …;``),
    each with its values in order (``--policy`` repeats); empty for any other line."""
    if not made_by:
        return {}
    command = made_by.removeprefix("#").strip().removeprefix("made by:").split(";")[0]
    try:
        words = shlex.split(command)
    except ValueError:
        return {}
    if words[1:2] != ["evaluate"]:
        return {}
    options: dict[str, list[str]] = {}
    for word, value in itertools.pairwise([*words[2:], ""]):
        if word.startswith("--") and not value.startswith("--"):
            options.setdefault(word, []).append(value)
    return options


def check_complete(path: object, frame: pd.DataFrame, made_by: str | None) -> None:
    """DamagedFileError (one line) if a cell ``made_by`` names has fewer rows in ``frame``
    (the checked trials) than the trials it names (times the policies, for a controller that
    pushes with them: ``rl``)."""
    options = named_options(made_by)
    if not options:
        return
    cells = []
    for column, option, groups in _DIMENSIONS:
        value = (options.get(option) or [""])[0]
        found = tuple(dict.fromkeys(frame[column]))
        if value in groups:
            named = groups[value]
            cells.append(named() if callable(named) else named)
        elif value and not value.lower().endswith(".toml"):
            cells.append(tuple(value.split(",")))
        else:
            cells.append(found)
    try:
        trials = int((options.get("--trials") or ["0"])[0])
    except ValueError:
        return
    policies = max(1, len(options.get("--policy", [])))
    counts = frame.groupby(["object", "profile", "plant", "controller"]).size()
    for cell in itertools.product(*cells):
        expected = trials * (policies if _by_policy(cell[3]) else 1)
        have = int(counts.get(cell, 0))
        if trials and have < expected:
            raise DamagedFileError(
                f"{path}: cut short or edited: its provenance line names {trials} trials of "
                f"{'/'.join(cell)}, it holds {have} of the {expected} rows; rerun "
                "`pushctl evaluate` to remake it"
            )


def _by_policy(name: str) -> bool:
    """Whether controller ``name`` adds a row per policy (an unknown name: no)."""
    try:
        return controller_entry(name).needs_policy
    except ConfigError:
        return False
