"""The ``pushctl`` command line: one module per command, each a Typer app with its one
command, composed into ``app`` in :mod:`pushctl.cli.commands`. Commands whose work imports
the core (torch, matplotlib, the simulator) keep that work in a ``*_steps`` module imported
only when the command runs, so ``pushctl --help`` stays fast.

- ``info``, ``plan``, ``simulate`` (:mod:`pushctl.cli.simulate_steps`), ``tune-pd``,
  ``tune-feedback`` (:mod:`pushctl.cli.tune_feedback_steps`), ``train``
  (:mod:`pushctl.cli.train_steps`; ``--seeds``: :mod:`pushctl.cli.train_seeds`),
  ``evaluate`` (:mod:`pushctl.cli.evaluate_steps`), ``report``
  (:mod:`pushctl.cli.report_steps`), ``sweep`` and ``reproduce``
  (:mod:`pushctl.reproduce.steps`: ``make reproduce-tables``, which runs the others);
- :mod:`pushctl.cli.common`: consoles, the one-line failure, provenance, atomic writes.

The core never imports this package: imports flow cli → report → runs → evaluation →
controllers → rl → task → episode → control / planning → contact → arm / objects
(tests/test_layout.py).

Importing this package changes nothing outside it: :func:`main`, the ``pushctl`` command,
pins the CPU code and drops stale kernel caches before it loads the commands; ``app`` (for
``CliRunner`` and embedding) loads them on first use.
"""

from __future__ import annotations

from typing import Any


def main() -> None:
    """The ``pushctl`` command: pin numpy's CPU code before anything loads numpy (the same
    bytes on every x86-64 machine), drop the kernel caches whose sources changed (numba's
    cache does not follow calls across files), then run the command line."""
    from pushctl.machine import reproducible
    from pushctl.machine.kernel_cache import drop_stale

    reproducible()
    drop_stale()
    from pushctl.cli.commands import app

    app(prog_name="pushctl")


def __getattr__(name: str) -> Any:
    if name == "app":
        from pushctl.cli.commands import app

        return app
    raise AttributeError(f"module 'pushctl.cli' has no attribute {name!r}")


__all__ = ["app", "main"]
