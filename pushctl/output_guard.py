"""No result is overwritten by accident: the checks every writing command makes before it works.

A command refuses, with one line naming ``--force``, to write

- into an output *directory* that already holds files (``pushctl evaluate``, ``pushctl train``),
- over an output *file* that already exists (``plan``/``simulate`` ``--out``/``--plot``,
  ``tune-pd``, ``report``'s tables and figures, ``python -m benchmarks.suite``,
  ``python -m studies.pd_sweep``),

unless the user passed ``--force``. The checks run before any work, so a refused command
costs nothing; the files are then written atomically (:func:`pushctl.provenance.write_atomic`),
so a file this run wrote is replaced only by a file the same run wrote.
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

from pushctl.errors import ConfigError


def refuse_existing_files(option: str, paths: Iterable[Path | None], force: bool) -> None:
    """ConfigError if any of ``paths`` (None entries skipped) already exists, unless ``force``.

    ``option`` names the command-line option the paths come from (``--out``), for the
    message."""
    if force:
        return
    for path in paths:
        if path is not None and path.exists():
            raise ConfigError(
                f"{option}: {path} already exists; pass --force to overwrite it, "
                "or choose another path"
            )


def refuse_occupied_dir(option: str, directory: Path, force: bool) -> None:
    """ConfigError if ``directory`` exists and holds anything, unless ``force``."""
    if force or not directory.is_dir():
        return
    if any(directory.iterdir()):
        raise ConfigError(
            f"{option}: {directory} is not empty; pass --force to overwrite the results in it, "
            "or choose another directory"
        )
