"""``pushctl realdata``: fit the contact model's friction to recorded pushes, score every
push beside a published model, replay the two-finger logs (docs/realdata.md)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from pushctl.cli.common import (
    FORCE_HELP,
    STOPPED,
    Command,
    Group,
    console,
    fail,
    fail_write,
    interrupted,
    invocation,
)
from pushctl.errors import ConfigError, PushctlError
from pushctl.files.output_guard import refuse_existing_files, refuse_occupied_dir

app = typer.Typer(
    cls=Group, no_args_is_help=True, help="Recorded pushes: fit, score, leave one shape out, logs."
)

DATA_HELP = "directory holding mit/pushes.csv, mit/shapes.csv (and two_finger_logs/)"
WORKERS_HELP = "worker processes for the replay (results do not depend on it)"
RIM_HELP = "the rim-weight grid the fit searches first, comma-separated (then +-1 around the best)"

# The options the subcommands share, declared once.
DataOption = Annotated[Path, typer.Option(help=DATA_HELP)]
OutDirOption = Annotated[Path, typer.Option(help="output directory (created if missing)")]
SplitSeedOption = Annotated[int, typer.Option(help="seed of the calibration split")]
FrictionModelOption = Annotated[
    str, typer.Option(help="ground friction: polygon, slip_box or axis_box")
]
FacetsOption = Annotated[
    int, typer.Option(help="the polygon's sides (a multiple of 4, >= 8; polygon model only)")
]
RimWeightsOption = Annotated[str, typer.Option(help=RIM_HELP)]
RIM_WEIGHTS = "-2,0,2,4,6,8"
"""The rim-weight grid ``fit`` and ``loso`` search first by default."""
WorkersOption = Annotated[int, typer.Option(help=WORKERS_HELP)]
ForceOption = Annotated[bool, typer.Option("--force", help=FORCE_HELP)]


@app.command(cls=Command)
def fit(
    ctx: typer.Context,
    data: DataOption,
    out: Annotated[Path, typer.Option(help="the fit, a .toml file")],
    split_seed: SplitSeedOption = 0,
    exclude_shape: Annotated[
        list[str], typer.Option(help="leave this shape out of the fit (repeatable)")
    ] = [],  # noqa: B006 (Typer reads the default)
    friction_model: FrictionModelOption = "polygon",
    facets: FacetsOption = 16,
    rim_weights: RimWeightsOption = RIM_WEIGHTS,
    workers: WorkersOption = 2,
    force: ForceOption = False,
) -> None:
    """Fit μ_c, μ_g and the pressure prior's rim weight per surface on a seeded 20 % split."""
    from pushctl.files.provenance import provenance_line
    from pushctl.realdata.protocol import run_fit
    from pushctl.realdata.replay import ReplaySettings

    try:
        _check_split_seed(split_seed)
        if out.suffix != ".toml":
            raise ConfigError(f"--out must end in .toml, got {str(out)!r}")
        if not out.parent.is_dir():
            raise ConfigError(f"--out: directory {str(out.parent)!r} does not exist")
        refuse_existing_files("--out", (out,), force)
        _check_workers(workers)
        settings = ReplaySettings(friction_model=friction_model, facets=facets)
        header = [provenance_line(_invocation(ctx))]
        text = run_fit(data, split_seed, exclude_shape, settings, header, workers,
                       progress=lambda line: console.print(line, highlight=False),
                       grids=_grids(rim_weights))  # fmt: skip
    except PushctlError as error:
        fail(error)
    except BaseException as error:
        _stopped(error)
    _write_text(out, text)


@app.command(cls=Command)
def score(
    ctx: typer.Context,
    data: DataOption,
    friction: Annotated[Path, typer.Option(help="a fit written by `pushctl realdata fit`")],
    out: OutDirOption,
    shapes: Annotated[
        list[str], typer.Option(help="score only pushes of this shape (repeatable)")
    ] = [],  # noqa: B006
    workers: WorkersOption = 2,
    force: ForceOption = False,
) -> None:
    """Replay every push; write predictions.csv, summary.csv and figures into OUT."""
    from pushctl.files.provenance import provenance_line, write_atomic, write_csv
    from pushctl.realdata import figures
    from pushctl.realdata.fit import read_friction
    from pushctl.realdata.protocol import run_score

    try:
        _prepare_dir(out, force)
        _check_workers(workers)
        params, settings, split = read_friction(friction)
        result = run_score(data, params, settings, split, shapes, workers)
    except PushctlError as error:
        fail(error)
    except BaseException as error:
        _stopped(error)
    line = provenance_line(_invocation(ctx))
    try:
        out.mkdir(exist_ok=True)
        write_csv(out / "predictions.csv", result.predictions, line)
        write_csv(out / "summary.csv", result.summary, line, float_format="%.6g")
        for name, fig in (
            ("displacement.png", figures.displacement_figure(result.pushes, result.ours,
                                                             result.zhou)),
            ("examples.png", figures.example_pushes_figure(result.pushes, result.shapes,
                                                           result.ours, result.zhou)),
        ):  # fmt: skip
            write_atomic(out / name, _png_writer(fig))
    except (OSError, PushctlError) as error:
        fail_write(error)
    _print_overall(result.summary)
    split_name = "test split" if result.split_known else "all pushes (unseen by the fit)"
    console.print(f"{len(result.pushes)} pushes replayed in {result.seconds:.1f} s; "
                  f"scored on the {split_name}; wrote {out}")  # fmt: skip


@app.command(cls=Command)
def loso(
    ctx: typer.Context,
    data: DataOption,
    out: OutDirOption,
    split_seed: SplitSeedOption = 0,
    friction_model: FrictionModelOption = "polygon",
    facets: FacetsOption = 16,
    rim_weights: RimWeightsOption = RIM_WEIGHTS,
    workers: WorkersOption = 2,
    force: ForceOption = False,
) -> None:
    """Leave one shape out: per shape, fit on the others' calibration pushes, score it."""
    from pushctl.files.provenance import provenance_line, write_csv
    from pushctl.realdata.loso import run_loso
    from pushctl.realdata.replay import ReplaySettings

    try:
        _check_split_seed(split_seed)
        _prepare_dir(out, force)
        _check_workers(workers)
        settings = ReplaySettings(friction_model=friction_model, facets=facets)
        result = run_loso(data, split_seed, settings, _grids(rim_weights), workers=workers,
                          progress=lambda line: console.print(line, highlight=False))  # fmt: skip
    except PushctlError as error:
        fail(error)
    except BaseException as error:
        _stopped(error)
    line = provenance_line(_invocation(ctx))
    try:
        out.mkdir(exist_ok=True)
        write_csv(out / "loso.csv", result.table, line, float_format="%.6g")
        write_csv(out / "groups.csv", result.groups, line, float_format="%.6g")
        write_csv(out / "predictions.csv", result.predictions, line)
    except (OSError, PushctlError) as error:
        fail_write(error)
    total = result.table.iloc[-1]
    zhou = f"; Zhou {total['zhou_nmse']:.3f}" if "zhou_nmse" in total else ""
    console.print(f"{int(total['n'])} held-out pushes: NMSE {total['nmse']:.3f}{zhou}; "
                  f"wrote {out}", highlight=False)  # fmt: skip


@app.command(cls=Command)
def logs(
    ctx: typer.Context,
    data: DataOption,
    out: OutDirOption,
    friction_model: FrictionModelOption = "polygon",
    facets: FacetsOption = 16,
    fit: Annotated[
        bool,
        typer.Option(
            "--fit", help="fit mu_c and the rim weight per setup on the other starts' segments"
        ),
    ] = False,
    force: ForceOption = False,
) -> None:
    """Replay each two-finger segment from its logged start; errors against the repeats."""
    from pushctl.files.provenance import provenance_line, write_atomic, write_csv
    from pushctl.kinematic import Friction, PressurePrior
    from pushctl.realdata.figures import logs_figure
    from pushctl.realdata.protocol import run_logs

    try:
        _prepare_dir(out, force)
        progress = lambda line: console.print(line, highlight=False)  # noqa: E731
        Friction(model=friction_model, facets=facets)  # the world's checks, before replays
        table, segments, replays = run_logs(data, PressurePrior(), friction_model, fit=fit,
                                            progress=progress, facets=facets)  # fmt: skip
    except PushctlError as error:
        fail(error)
    try:
        out.mkdir(exist_ok=True)
        write_csv(out / "segments.csv", table, provenance_line(_invocation(ctx)), "%.6g")
        fig = logs_figure(segments, replays)
        write_atomic(out / "paths.png", _png_writer(fig))
    except (OSError, PushctlError) as error:
        fail_write(error)
    share = table["within_3x_floor"].mean()
    console.print(f"{len(table)} segments; end error within 3x the repeat floor on "
                  f"{100 * share:.0f} %; median path RMSE "
                  f"{table['path_rmse_mm'].median():.2f} mm; wrote {out}")  # fmt: skip


def _stopped(error: BaseException) -> None:
    """End a command stopped during its replay in one line: Ctrl-C or SIGTERM (the replay's
    workers stop with it), or a worker process killed on its own; re-raise anything else."""
    from concurrent.futures.process import BrokenProcessPool

    if isinstance(error, KeyboardInterrupt) or (
        isinstance(error, BrokenProcessPool) and STOPPED["terminated"]
    ):
        interrupted("nothing written; run the command again")
    if isinstance(error, BrokenProcessPool):
        fail(PushctlError("a replay worker process ended unexpectedly (killed?); nothing written"))
    raise error


def _png_writer(fig):
    """A writer for :func:`~pushctl.files.provenance.write_atomic` saving ``fig`` as PNG."""

    def write(tmp: Path) -> None:
        fig.savefig(tmp, format="png", dpi=120)

    return write


def _invocation(ctx: typer.Context) -> str:
    """The command line for provenance lines, with this sub-app's name."""
    return invocation(ctx).replace("pushctl ", "pushctl realdata ", 1)


def _grids(rim_weights: str):
    """The fit's grids with the rim-weight grid ``rim_weights`` ("-2,0,2,4,6,8")."""
    from pushctl.kinematic import PressurePrior
    from pushctl.realdata.fit import FitGrids

    try:
        grid = tuple(float(w) for w in rim_weights.split(","))
    except ValueError:
        raise ConfigError(
            f"--rim-weights: expected numbers like -2,0,2, got {rim_weights!r}"
        ) from None
    for w in grid:
        PressurePrior(rim_weight=w)  # |w| <= 20
    return FitGrids(rim_weight=grid)


def _check_split_seed(seed: int) -> None:
    if seed < 0:
        raise ConfigError(f"--split-seed must be an integer >= 0, got {seed}")


def _check_workers(workers: int) -> None:
    if workers < 1:
        raise ConfigError(f"--workers must be >= 1, got {workers}")


def _prepare_dir(out: Path, force: bool) -> None:
    """Checks before any work: OUT is a directory (or absent) and holds no results."""
    if out.exists() and not out.is_dir():
        raise ConfigError(f"--out: {out} is a file, expected a directory")
    if not out.exists() and not out.parent.is_dir():
        raise ConfigError(f"--out: directory {str(out.parent)!r} does not exist")
    refuse_occupied_dir("--out", out, force)


def _write_text(path: Path, text: str) -> None:
    from pushctl.files.provenance import write_atomic

    try:
        write_atomic(path, lambda tmp: tmp.write_text(text))
    except (OSError, PushctlError) as error:
        fail_write(error)
    console.print(f"wrote {path}")


def _print_overall(summary) -> None:
    rows = summary[summary["surface"] == "all"]
    for _, row in rows.iterrows():
        zhou = f"; Zhou {row['zhou_nmse']:.3f}" if "zhou_nmse" in row else ""
        console.print(
            f"{row['split']}: n {int(row['n'])}, NMSE {row['nmse']:.3f} (x {row['nmse_x']:.3f}, "
            f"y {row['nmse_y']:.3f}, θ {row['nmse_theta']:.3f}), "
            f"{row['position_error_mm']:.1f} mm, {row['angle_error_deg']:.1f}°{zhou}",
            highlight=False,
        )
