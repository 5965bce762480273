"""This tree against another commit, side by side: opt-in, not part of ``make bench``.

Run from the checkout's root as ``python -m benchmarks.compare_commits WHAT --against REV
[options]``, REV any commit of this checkout's git history (a shallow clone may lack it:
``git fetch --unshallow``). WHAT is

- ``step``: the world step, cold MLCP solves and env steps (:mod:`benchmarks.commits.step`);
- ``evaluate``: a short ``pushctl evaluate`` timed, the outputs compared byte for byte
  (:mod:`benchmarks.commits.evaluate`);
- ``train``: a short ``paper``-shaped ``pushctl train``, likewise
  (:mod:`benchmarks.commits.train`).

``python -m benchmarks.compare_commits WHAT --help`` lists each one's options.
"""

from __future__ import annotations

import importlib
import sys

BENCHES = {
    "step": "benchmarks.commits.step",
    "evaluate": "benchmarks.commits.evaluate",
    "train": "benchmarks.commits.train",
}


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if not args or args[0] not in BENCHES:
        given = f"got {args[0]!r}" if args else "got nothing"
        print(f"error: give what to compare, one of {', '.join(BENCHES)}; {given}",
              file=sys.stderr)  # fmt: skip
        return 2
    return importlib.import_module(BENCHES[args[0]]).main(args[1:])


if __name__ == "__main__":
    raise SystemExit(main())
