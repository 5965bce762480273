"""What every ``pushctl`` command shares: the consoles, the one-line failure, the
provenance of the running command, atomic writes of its outputs, and the parsing of poses
and output paths. Light on purpose: ``pushctl --help`` imports it and nothing of the core."""

from __future__ import annotations

import math
from pathlib import Path
from typing import NoReturn

import typer
from rich.console import Console
from typer.core import TyperCommand

from pushctl.errors import ConfigError, PushctlError

console = Console()
error_console = Console(stderr=True, soft_wrap=True)
FORCE_HELP = "overwrite existing results in the output path"
OBJECT_HELP = "cube, wedge, or a TOML object file (e.g. experiments/objects/hexagon.toml)"
ARM_HELP = "kinova-gen2-7dof, kinova-j2s6s200 or panda"
PUSHER_HELP = "pusher file: k = 1-4 prongs, spacing, plate, mass (experiments/pushers/*.toml)"
PUSHER_DEFAULT = "the paper's two-prong plate"


SECONDS = "[s]"
KILOGRAMS = "[kg]"
DIMENSIONLESS = "[1]"
POSE = "x[m],y[m],θ[deg]"
"""Units shown in ``--help`` as the value's placeholder (``--duration [s]``), one per
physical option: rich reads brackets in help text as markup, so they go here."""
RENAMED_HELP = "renamed; still accepted"


class Command(TyperCommand):
    """Every ``pushctl`` command's class: in ``--help`` a flag (an option that takes no
    value, ``--force``) shows no value placeholder, as it takes none."""

    def get_params(self, ctx):  # noqa: ANN001, ANN201 (click's signature)
        params = super().get_params(ctx)
        for param in params:
            if getattr(param, "is_flag", False):
                param.metavar = ""
        return params


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


def fail_write(error: OSError) -> NoReturn:
    """:func:`fail` for a file that could not be written."""
    fail(PushctlError(f"cannot write {error.filename}: {error.strerror}"))


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
    from pushctl.provenance import write_atomic

    def write(tmp: Path) -> None:
        tmp.write_text(text)

    try:
        write_atomic(path, write)
    except OSError as error:
        fail_write(error)
    console.print(f"wrote {path}")


def write_outputs(
    command: str, out: Path | None, frame, plot: Path | None, figure, extra: str
) -> None:
    """The figure, then the CSV (under its provenance line), each written atomically; the
    CSV's temporary file is renamed only once the figure is in place, so a failure leaves
    either both new files or no new CSV."""
    from pushctl.provenance import provenance_line, write_atomic, write_csv

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
    except OSError as error:
        fail_write(error)


def invocation(context: typer.Context) -> str:
    """The running command with every option's effective value (defaults included, unset
    options and :data:`~pushctl.provenance.NOT_RECORDED` left out), for provenance lines:
    ``pushctl simulate --object cube …``."""
    import shlex

    from pushctl.provenance import NOT_RECORDED

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
