"""The ``pushctl`` command line: one module per command, each a Typer app with its one
command, composed here into ``app`` (Typer merges an unnamed sub-app's commands into the
top level). Commands whose work imports the core (torch, matplotlib, the simulator) keep
that work in a ``*_steps`` module imported only when the command runs, so ``pushctl
--help`` stays fast.

- ``info``, ``plan``, ``simulate`` (:mod:`pushctl.cli.simulate_steps`), ``tune-pd``,
  ``tune-feedback`` (:mod:`pushctl.cli.tune_feedback_steps`), ``train``
  (:mod:`pushctl.cli.train_steps`; ``--seeds``: :mod:`pushctl.cli.train_seeds`),
  ``evaluate`` (:mod:`pushctl.cli.evaluate_steps`), ``report``
  (:mod:`pushctl.cli.report_steps`), ``sweep`` and ``reproduce``
  (:mod:`pushctl.cli.reproduce_steps`: ``make reproduce-tables``, which runs the others);
- :mod:`pushctl.cli.common`: consoles, the one-line failure, provenance, atomic writes.

The core never imports this package: imports flow cli → evaluation / rl → episode →
control / planning → contact → arm / objects (tests/test_layout.py).
"""

from __future__ import annotations

from pushctl.kernel_cache import drop_stale
from pushctl.machine import reproducible

reproducible()  # before anything loads numpy: the same bytes on every x86-64 machine
drop_stale()  # before any kernel loads: numba's cache does not follow calls across files

import typer  # noqa: E402

from pushctl.cli import (  # noqa: E402
    evaluate,
    info,
    plan,
    report,
    reproduce,
    simulate,
    sweep,
    train,
    tune_feedback,
    tune_pd,
)

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    help="Multi-point object pushing with a redundant arm: simulate, plan, train, evaluate.",
)


@app.callback()
def _main() -> None:
    """pushctl: multi-point object pushing experiments."""


_COMMANDS = (info, plan, simulate, tune_pd, tune_feedback, train, evaluate, report, sweep)
for _command in (*_COMMANDS, reproduce):  # reproduce: make reproduce-tables, the others in turn
    app.add_typer(_command.app)

__all__ = ["app"]
