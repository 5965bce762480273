"""The README's *Does it work?* table, rendered from a results directory's CSVs.

``python -m studies.readme_table results`` prints its six rows (one per object and
profile): `sim`'s tracking means for PD-only / feedback / RL, RL/PD as the ratio of the means
on `sim`, `proxy` and `mujoco`, and `sim`'s two force errors in mN. Every number comes from
``table3.csv``, ``table3_proxy.csv`` and ``table4.csv`` as ``pushctl report`` wrote them, so
``tests/test_readme.py`` can check that the README shows the shipped run.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pandas as pd

TABLES = ("table3.csv", "table3_proxy.csv", "table4.csv")
"""The report's tables the README's table reads."""


def _read(directory: Path, name: str) -> pd.DataFrame:
    return pd.read_csv(directory / name, comment="#")


CONTROLLERS = ("pd", "feedback", "rl")


def _triple(row: pd.Series, column: str, digits: int) -> str:
    """``column`` (with ``{c}`` for the controller) for PD-only / feedback / RL."""
    return " / ".join(f"{row[column.format(c=c)]:.{digits}f}" for c in CONTROLLERS)


def _ratios(row: pd.Series, suffix: str = "") -> str:
    translation = row[f"translation_error_rl{suffix}"] / row[f"translation_error_pd{suffix}"]
    angle = row[f"angle_error_rl{suffix}"] / row[f"angle_error_pd{suffix}"]
    return f"{translation:.2f}, {angle:.2f}"


def readme_rows(directory: Path) -> list[str]:
    """The table's Markdown rows (no header) from ``directory``'s tables."""
    sim = _read(directory, "table3.csv")
    proxy = _read(directory, "table3_proxy.csv").set_index(["object", "profile"])
    forces = _read(directory, "table4.csv").set_index(["object", "profile"])
    rows = []
    for _, row in sim.iterrows():
        cell = (row.object, row.profile)
        force = forces.loc[cell] * 1000.0  # N → mN
        cells = [
            f"{row.object}, {row.profile}",
            _triple(row, "translation_error_{c}", 3),
            _triple(row, "angle_error_{c}", 2),
            _ratios(row),
            _ratios(proxy.loc[cell]),
            _ratios(row, "_mujoco"),
            _triple(force, "force_error_{c}_sim", 1),
            _triple(force, "force_error_landed_{c}_sim", 1),
        ]
        rows.append("| " + " | ".join(cells) + " |")
    return rows


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    directory = Path(args[0]) if args else Path("results")
    missing = [name for name in TABLES if not (directory / name).is_file()]
    if missing:
        print(
            f"error: {directory} has no {', '.join(missing)}; give a directory that "
            "`pushctl report` wrote (e.g. results)",
            file=sys.stderr,
        )
        return 2
    print("\n".join(readme_rows(directory)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
