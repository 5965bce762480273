"""The defaults every command and registered environment runs with, shipped as package data:
the PD gains (``pd_gains.toml``), the feedback law's gains (``feedback_gains.toml``; the
steady law without a catch-up phase, ``feedback_gains_v1.toml``), the randomisation ranges
(``randomisation.toml``) and the named training presets (``train_quick.toml``,
``train_paper.toml``).

They belong to the installed version: nothing writes them, so a registered environment id
runs the same defaults until pushctl itself changes. A user's own gains, ranges or presets
live anywhere (a checkout's ``experiments/`` holds the project's) and are given by path.
"""

from __future__ import annotations

from importlib.resources import files
from pathlib import Path


def default_file(name: str) -> Path:
    """The path of the shipped default file ``name`` (e.g. ``"pd_gains.toml"``)."""
    return Path(str(files(__name__).joinpath(name)))
