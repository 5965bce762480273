"""The ``pushctl`` command line: one module per command, each a Typer app with its one
command, composed here into ``app`` (Typer merges an unnamed sub-app's commands into the
top level). Commands whose work imports the core (torch, matplotlib, the simulator) keep
that work in a ``*_steps`` module imported only when the command runs, so ``pushctl
--help`` stays fast.

- ``info``, ``plan``, ``simulate`` (:mod:`pushctl.cli.simulate_steps`), ``tune-pd``,
  ``tune-feedback`` (:mod:`pushctl.cli.tune_feedback_steps`), ``train``
  (:mod:`pushctl.cli.train_steps`; ``--seeds``: :mod:`pushctl.cli.train_seeds`),
  ``evaluate`` (:mod:`pushctl.cli.evaluate_steps`), ``report``
  (:mod:`pushctl.cli.report_steps`) and ``sweep``;
- :mod:`pushctl.cli.common`: consoles, the one-line failure, provenance, atomic writes;
- :mod:`pushctl.cli.reproduce`: ``make reproduce-tables``, which runs these commands.

The core never imports this package: imports flow cli → evaluation / rl → episode →
control / planning → contact → arm / objects (tests/test_layout.py).
"""

from __future__ import annotations

import typer

from pushctl.cli import (
    evaluate,
    info,
    plan,
    realdata,
    report,
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


for _command in (info, plan, simulate, tune_pd, tune_feedback, train, evaluate, report, sweep):
    app.add_typer(_command.app)
app.add_typer(realdata.app, name="realdata")

__all__ = ["app"]
