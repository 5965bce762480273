"""Reading the project's TOML files (objects, gains, ranges) with one-line errors."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from pushctl.errors import ConfigError

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10: the same parser is published as tomli
    import tomli as tomllib  # type: ignore[no-redef]


def read_toml(path: Path, kind: str) -> dict[str, Any]:
    """The table in ``path``; ConfigError naming the ``kind`` of file (``"gains file"``) and
    the path if it is missing, unreadable or not valid TOML."""
    try:
        with path.open("rb") as stream:
            return tomllib.load(stream)
    except FileNotFoundError:
        raise ConfigError(f"{kind} {path} does not exist") from None
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
        reason = " ".join(str(exc).split())
        raise ConfigError(f"cannot read {kind} {path}: {reason}") from None


def check_keys(
    table: Mapping[str, Any], names: list[str], where: str, *, all_required: bool = True
) -> None:
    """ConfigError unless ``table``'s keys are among ``names`` and, with ``all_required``,
    are all of them; ``where`` names the table in the message (``"[pd]"``)."""
    unknown = sorted(str(key) for key in set(table) - set(names))
    missing = [name for name in names if name not in table] if all_required else []
    if unknown or missing:
        problem = f"unknown keys {unknown}" if unknown else f"missing keys {missing}"
        raise ConfigError(f"{where} has {problem}; accepted: {', '.join(names)}")
