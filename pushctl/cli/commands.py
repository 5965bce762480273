"""The ``pushctl`` command's Typer app: one module per command, each a Typer app with its
one command, composed here into ``app`` (Typer merges an unnamed sub-app's commands into the
top level). Importing it loads numpy (through the commands' option types and checks), so
the ``pushctl`` command pins the CPU code first (:func:`pushctl.cli.main`)."""

from __future__ import annotations

import sys
from typing import Annotated, Any

import typer

try:  # Typer >= 0.20 carries its own copy of click, whose exceptions its commands raise
    from typer._click import exceptions as click
except ImportError:  # pragma: no cover - older Typer runs on click itself
    from click import exceptions as click  # type: ignore[no-redef]

from pushctl.cli import (
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
from pushctl.cli.common import Group


class _OneLineErrors(Group):
    """pushctl's command group: a usage error (a missing or unknown option, a value that is
    not a number) is one ``error:`` line and exit code 2, as every other bad input is,
    instead of click's multi-line usage box."""

    def main(self, args=None, prog_name=None, complete_var=None, standalone_mode=True, **extra):
        if not standalone_mode:
            return super().main(args, prog_name, complete_var, standalone_mode, **extra)
        from pushctl.cli.common import STOPPED, error_console

        STOPPED.update(terminated=False, said=False)
        try:
            _refuse_repeated(self, sys.argv[1:] if args is None else list(args))
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


_LISTS = ("--controller", "--object", "--profile", "--plant")
"""Options that take several names as one comma-separated value (``pd,feedback``)."""


def _refuse_repeated(group: Any, args: list[str]) -> None:
    """A UsageError if an option of :data:`_LISTS` is given twice: click keeps the last
    value silently, so ``--controller pd --controller feedback`` would run feedback alone.
    (Other options keep click's rule, the last value wins, so a command can be extended.)"""
    seen: set[str] = set()
    for token in args:
        if token == "--":
            break
        name = token.split("=", 1)[0]
        if name in _LISTS:
            if name in seen:
                raise click.UsageError(
                    f"{name} was given twice; give several names as one comma-separated "
                    f"value, e.g. {name} a,b"
                )
            seen.add(name)


app = typer.Typer(
    cls=_OneLineErrors,
    add_completion=False,
    no_args_is_help=True,
    help="Multi-point object pushing with a redundant arm: simulate, plan, train, evaluate.",
)


def _show_version(value: bool) -> None:
    if value:
        from pushctl.version import VERSION

        print(f"pushctl {VERSION}")
        raise typer.Exit()


@app.callback()
def _main(
    ctx: typer.Context,
    version: Annotated[
        bool,
        typer.Option(
            "--version", callback=_show_version, is_eager=True, help="Show the version and exit."
        ),
    ] = False,
) -> None:
    """pushctl: multi-point object pushing experiments."""
    from pushctl.cli.common import handle_termination
    from pushctl.files.output_guard import release

    handle_termination()  # SIGTERM stops a command as Ctrl-C does, with exit code 143
    ctx.call_on_close(release)  # the outputs a command locked, however it ends


_COMMANDS = (info, plan, simulate, tune_pd, tune_feedback, train, evaluate, report, sweep)
for _command in (*_COMMANDS, reproduce):  # reproduce: make reproduce-tables, the others in turn
    app.add_typer(_command.app)
app.add_typer(realdata.app, name="realdata")

__all__ = ["app"]
