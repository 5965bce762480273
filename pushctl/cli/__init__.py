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

The core never imports this package: imports flow cli → evaluation → controllers → rl →
episode → control / planning → contact → arm / objects (tests/test_layout.py).
"""

from __future__ import annotations

import sys

from pushctl.kernel_cache import drop_stale
from pushctl.machine import reproducible

reproducible()  # before anything loads numpy: the same bytes on every x86-64 machine
drop_stale()  # before any kernel loads: numba's cache does not follow calls across files

import typer  # noqa: E402
from typer.core import TyperGroup  # noqa: E402

try:  # Typer >= 0.20 carries its own copy of click, whose exceptions its commands raise
    from typer._click import exceptions as click
except ImportError:  # pragma: no cover - older Typer runs on click itself
    from click import exceptions as click  # type: ignore[no-redef]

from pushctl.cli import (  # noqa: E402
    evaluate,
    info,
    plan,
    realdata,
    report,
    reproduce,
    simulate,
    sweep,
    train,
    tune_feedback,
    tune_pd,
)


class _OneLineErrors(TyperGroup):
    """pushctl's command group: a usage error (a missing or unknown option, a value that is
    not a number) is one ``error:`` line and exit code 2, as every other bad input is,
    instead of click's multi-line usage box."""

    def main(self, args=None, prog_name=None, complete_var=None, standalone_mode=True, **extra):
        if not standalone_mode:
            return super().main(args, prog_name, complete_var, standalone_mode, **extra)
        from pushctl.cli.common import STOPPED, error_console

        STOPPED.update(terminated=False, said=False)
        try:
            code = super().main(args, prog_name, complete_var, False, **extra)
        except click.NoArgsIsHelpError:
            return super().main(args, prog_name, complete_var, True, **extra)  # the help
        except click.ClickException as error:
            message = " ".join(error.format_message().split())
            hint = " (see --help)" if isinstance(error, click.UsageError) else ""
            error_console.print(f"error: {message}{hint}", markup=False, highlight=False)
            sys.exit(2 if isinstance(error, click.UsageError) else error.exit_code)
        except KeyboardInterrupt:
            code = 130
        if code == 130 or STOPPED["terminated"]:  # Typer ends a stray Ctrl-C silently
            terminated = STOPPED["terminated"]
            if not STOPPED["said"]:
                word = "terminated" if terminated else "interrupted"
                error_console.print(f"{word}: stopped", markup=False, highlight=False)
            sys.exit(143 if terminated else 130)
        sys.exit(code if isinstance(code, int) else 0)


app = typer.Typer(
    cls=_OneLineErrors,
    add_completion=False,
    no_args_is_help=True,
    help="Multi-point object pushing with a redundant arm: simulate, plan, train, evaluate.",
)


@app.callback()
def _main(ctx: typer.Context) -> None:
    """pushctl: multi-point object pushing experiments."""
    from pushctl.cli.common import handle_termination
    from pushctl.output_guard import release

    handle_termination()  # SIGTERM stops a command as Ctrl-C does, with exit code 143
    ctx.call_on_close(release)  # the outputs a command locked, however it ends


_COMMANDS = (info, plan, simulate, tune_pd, tune_feedback, train, evaluate, report, sweep)
for _command in (*_COMMANDS, reproduce):  # reproduce: make reproduce-tables, the others in turn
    app.add_typer(_command.app)
app.add_typer(realdata.app, name="realdata")

__all__ = ["app"]
