"""What every ``pushctl`` command shares: the consoles, the one-line failure, the
provenance of the running command, atomic writes of its outputs, and the parsing of poses
and output paths. Light on purpose: ``pushctl --help`` imports it and nothing of the core."""

from __future__ import annotations

import math
import sys
from pathlib import Path
from typing import NoReturn

import typer
from rich.console import Console
from typer.core import TyperCommand, TyperGroup

from pushctl.controllers import entries
from pushctl.errors import ConfigError, PushctlError

console = Console()
error_console = Console(stderr=True, soft_wrap=True)
FORCE_HELP = "overwrite existing results in the output path"
OBJECT_HELP = "cube, wedge, or a TOML object file (e.g. experiments/objects/hexagon.toml)"
ARM_HELP = "kinova-gen2-7dof, kinova-j2s6s200 or panda"
PUSHER_HELP = "pusher file: k = 1-4 prongs, spacing, plate, mass (experiments/pushers/*.toml)"


def controller_help(every: str | None = None) -> str:
    """``--controller``'s help from the registry: each name with its summary, then
    ``every`` (the choice of several), e.g. ``pd (PD-only), …``."""
    named = [f"{entry.name} ({entry.summary})" for entry in entries()]
    if every is None:
        return ", ".join(named[:-1]) + " or " + named[-1] if len(named) > 1 else named[0]
    return ", ".join([*named, every])


PUSHER_DEFAULT = "the paper's two-prong plate"


SECONDS = "[s]"
KILOGRAMS = "[kg]"
DIMENSIONLESS = "[1]"
POSE = "x[m],y[m],θ[deg]"
"""Units shown in ``--help`` as the value's placeholder (``--duration [s]``), one per
physical option: rich reads brackets in help text as markup, so they go here."""
RENAMED_HELP = "renamed; still accepted"


class _FlagsShowNoValue:
    """In ``--help`` a flag (an option that takes no value, ``--force``) shows no value
    placeholder, as it takes none."""

    def get_params(self, ctx):  # noqa: ANN001, ANN201 (click's signature)
        params = super().get_params(ctx)  # type: ignore[misc]
        for param in params:
            if getattr(param, "is_flag", False):
                param.metavar = ""
        return params


class Command(_FlagsShowNoValue, TyperCommand):
    """Every ``pushctl`` command's class."""


class Group(_FlagsShowNoValue, TyperGroup):
    """A command group's class (``pushctl realdata``)."""


def renamed_option(old: str) -> typer.models.OptionInfo:
    """A hidden option under an option's old name, so scripts written for it still run;
    :func:`take_renamed` folds its value into the new option's."""
    return typer.Option(old, hidden=True, help=RENAMED_HELP)


def take_renamed(ctx: typer.Context, new: str, value, old: str, old_value):  # noqa: ANN001, ANN201
    """``old_value`` if the old spelling ``old`` was given (saying so on stderr), else
    ``value``; the context then records it under the new name (for the provenance line)."""
    if old_value is None:
        return value
    error_console.print(f"note: {old} is now {new}", markup=False, highlight=False)
    name = next(p.name for p in ctx.command.params if new in p.opts)
    ctx.params[name] = old_value
    return old_value


def fail(error: PushctlError) -> NoReturn:
    """One line on stderr, exit code 2, no traceback."""
    error_console.print(f"error: {error}", markup=False, highlight=False)
    raise typer.Exit(code=2)


def fail_write(error: OSError | PushctlError, path: Path | None = None) -> NoReturn:
    """:func:`fail` for a file that could not be written: the file (``path``, else the one
    the error names) and the system's reason."""
    if isinstance(error, PushctlError):
        fail(error)
    from pushctl.files.provenance import write_failure

    target = path if path is not None else error.filename
    where = f" {target}" if target is not None else ""
    fail(PushctlError(f"cannot write{where}: {write_failure(error, Path(str(target or '.')))}"))


class Terminated(KeyboardInterrupt):
    """SIGTERM received: raised in the main thread where Ctrl-C raises KeyboardInterrupt,
    so a terminated command stops the way an interrupted one does (its ``finally`` blocks
    shut Ray down, its handler prints what was kept), with exit code 143 instead of 130."""


def handle_termination() -> None:
    """Make SIGTERM raise :class:`Terminated` in this process (the main thread only can
    set a handler; elsewhere nothing changes)."""
    import signal
    import threading

    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, _terminate)
        sys.unraisablehook = _raise_again_where_it_counts


def _raise_again_where_it_counts(unraisable) -> None:  # noqa: ANN001 (sys.UnraisableHookArgs)
    """A SIGTERM whose :class:`Terminated` was raised inside a callback Python cannot stop
    (a weakref callback during an import) would only be printed as "Exception ignored":
    send it again, so that it stops the command at its next step instead."""
    import os
    import signal

    if isinstance(unraisable.exc_value, Terminated):
        os.kill(os.getpid(), signal.SIGTERM)
        return
    sys.__unraisablehook__(unraisable)


STOPPED = {"terminated": False, "said": False}
"""Whether SIGTERM arrived, and whether the command said what it kept (:func:`interrupted`):
the app ends a stopped command that did not with one line and the right exit code."""


def _terminate(signum: int, frame: object) -> None:
    STOPPED["terminated"] = True
    raise Terminated


def interrupted(message: str) -> NoReturn:
    """End a command stopped by Ctrl-C (exit code 130) or SIGTERM (143) with one line on
    stderr: ``interrupted: <message>`` (what was kept, how to continue)."""
    import sys

    terminated = isinstance(sys.exc_info()[1], Terminated) or STOPPED["terminated"]
    STOPPED["said"] = True
    word = "terminated" if terminated else "interrupted"
    error_console.print(f"{word}: {message}", markup=False, highlight=False)
    raise typer.Exit(code=143 if terminated else 130)


def fail_ray(error: Exception) -> NoReturn:
    """One line and exit code 1 for a failure of Ray itself (one of its processes killed, a
    node lost), which retrying the calls did not mend; any other exception is re-raised (a
    bug, to be reported with its traceback)."""
    if not type(error).__module__.startswith("ray"):
        raise error
    from pushctl.files.provenance import one_line

    reason = one_line(str(error).split("\n", 1)[0], 120) or type(error).__name__
    error_console.print(
        f"error: Ray failed ({type(error).__name__}: {reason}); what was checkpointed is "
        "kept: run the command again with --resume",
        markup=False,
        highlight=False,
    )
    raise typer.Exit(code=1)


POSE_FORMAT = "x,y,theta_deg (metres, metres, degrees), e.g. 0.62,0.03,30"
PLOT_SUFFIXES = (".png", ".pdf", ".svg")


def parse_pose(option: str, text: str) -> tuple[float, float, float]:
    """``"x,y,theta_deg"`` → (x [m], y [m], θ [rad]); ConfigError naming ``option``."""
    parts = text.replace(" ", "").split(",")
    try:
        x, y, theta_deg = (float(part) for part in parts)
    except ValueError:
        raise ConfigError(f"{option} must be {POSE_FORMAT}; got {text!r}") from None
    if not all(math.isfinite(v) for v in (x, y, theta_deg)):
        raise ConfigError(f"{option} must be finite numbers {POSE_FORMAT}; got {text!r}")
    from pushctl.ranges import check_range

    for quantity, value in (("position", x), ("position", y), ("angle", theta_deg)):
        check_range(quantity, value, f"{option}: ")
    return x, y, math.radians(theta_deg)


def check_output(option: str, path: Path | None, suffixes: tuple[str, ...]) -> None:
    """ConfigError unless ``path`` can be written: existing directory, accepted suffix."""
    if path is None:
        return
    if path.suffix.lower() not in suffixes:
        raise ConfigError(f"{option} must end in {', '.join(suffixes)}; got {str(path)!r}")
    if not path.parent.is_dir():
        raise ConfigError(f"{option}: directory {str(path.parent)!r} does not exist")
    if path.is_dir():
        raise ConfigError(f"{option}: {str(path)!r} is a directory, expected a file name")


def write_text(path: Path, text: str) -> None:
    from pushctl.files.provenance import write_atomic

    def write(tmp: Path) -> None:
        tmp.write_text(text)

    try:
        write_atomic(path, write)
    except (OSError, PushctlError) as error:
        fail_write(error, path)
    console.print(f"wrote {path}")


def write_outputs(
    command: str, out: Path | None, frame, plot: Path | None, figure, extra: str
) -> None:
    """The figure, then the CSV (under its provenance line), each written atomically; the
    CSV's temporary file is renamed only once the figure is in place, so a failure leaves
    either both new files or no new CSV."""
    from pushctl.files.provenance import provenance_line, write_atomic, write_csv

    def save_figure() -> None:
        if plot is not None and figure is not None:
            write_atomic(plot, lambda tmp: figure.savefig(tmp, format=plot.suffix[1:], dpi=150))
            console.print(f"wrote {plot}")

    try:
        if out is not None and frame is not None:
            write_csv(out, frame, provenance_line(command, extra), before_rename=save_figure)
            console.print(f"wrote {out}")
        else:
            save_figure()
    except (OSError, PushctlError) as error:
        fail_write(error, out if out is not None else plot)


def invocation(context: typer.Context) -> str:
    """The running command with every option's effective value (defaults included, unset
    options and :data:`~pushctl.files.provenance.NOT_RECORDED` left out), for provenance lines:
    ``pushctl simulate --object cube …``."""
    import shlex

    from pushctl.files.provenance import NOT_RECORDED

    parts = ["pushctl", context.info_name or ""]
    for param in context.command.params:
        value = context.params.get(param.name or "")
        if value is None or value is False or not param.opts or param.name in NOT_RECORDED:
            continue
        if getattr(param, "hidden", False):  # an old spelling: recorded under the new one
            continue
        if isinstance(value, (list, tuple)):  # a repeated option (evaluate's --policy)
            parts += [part for one in value for part in (param.opts[0], str(one))]
            continue
        parts += [param.opts[0]] if value is True else [param.opts[0], str(value)]
    return shlex.join(parts)
