"""Tables III and IV from the per-trial CSV: means over the trials with 95 % confidence
intervals, one row per (object, profile).

- :func:`table3`: translation and angle error [%] of PD-only and RL-assisted on the ``sim``
  plant (the paper's Table III, which it measured on its real robot).
- :func:`table4`: force [N] and torque [N·m] error of PD-only and RL-assisted on the
  ``sim`` and ``proxy`` plants (the paper's Table IV, sim against real).

Each value column ``c`` is followed, after all value columns, by ``c_ci95``: the half-width
of the 95 % confidence interval of the mean, t(0.975, n − 1) · s / √n with s the sample
standard deviation (n − 1 in the denominator) and n the number of *finite* values: a
straight push has no angle error % (NaN), so it is left out of that mean and its n. A
cell with no finite value is NaN, one with a single value has a NaN interval.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy import stats

from pushctl.controllers import controller_entry, entries

OBJECT_ORDER = ("cube", "wedge")
PROFILE_ORDER = ("constant", "trapezoid", "chirp")
CONFIDENCE = 0.95

Source = tuple[str, str, str]
"""(metric column of trials.csv, plant, controller) a table column is the mean of."""

INTERVALS_NOTE = (
    "# intervals: every _ci95 column is the half-width of the 95 % confidence interval "
    "(Student t) of the mean over the cell's trials, RL's of its per-trial mean over the "
    "training seeds; a _seed_sd column is the standard deviation across the training seeds "
    "of their own cell means"
)
"""The tables' second comment line: what their intervals are across."""

FORCE_METRICS = ("force_error", "force_error_landed", "force_error_plan", "torque_error")
"""Table IV's metrics: force against the plant's needs with the prongs at the plan's spot and
where they landed, and against the nominal plan [N]; torque [N·m]."""
BEHAVIOUR_METRICS = ("slip_fraction", "contact_loss_fraction", "gate_open_fraction")


def tabled_controllers(trials: pd.DataFrame | None = None) -> tuple[str, ...]:
    """The tables' controllers, in the registry's order: the paper's comparison (PD-only,
    feedback, RL-assisted; there whether they ran or not), then any other registered
    controller that has rows in ``trials``."""
    ran = set() if trials is None else set(trials["controller"])
    return tuple(entry.name for entry in entries() if entry.paper or entry.name in ran)


def tracking_columns(plant: str, controllers: tuple[str, ...]) -> dict[str, Source]:
    """Table III's columns (translation and angle error [%] per controller) on ``plant``."""
    return {
        f"{name}_error_{controller}": (f"{name}_error_pct", plant, controller)
        for name in ("translation", "angle")
        for controller in controllers
    }


def force_columns(controllers: tuple[str, ...]) -> dict[str, Source]:
    """Table IV's columns (:data:`FORCE_METRICS` per controller on ``sim`` and ``proxy``)."""
    return {
        f"{metric}_{controller}_{plant}": (metric, plant, controller)
        for metric in FORCE_METRICS
        for controller in controllers
        for plant in ("sim", "proxy")
    }


def behaviour_columns(controllers: tuple[str, ...]) -> dict[str, Source]:
    """``behaviour.csv``'s columns [share of the push's steps]: with a slipping prong, with a
    prong out of contact, and (a controller with a gate) with the gate open, per controller
    and plant: where PD-only never slips or loses contact, a residual has little to fix
    (docs/design.md §6)."""
    return {
        f"{metric}_{controller}_{plant}": (metric, plant, controller)
        for metric in BEHAVIOUR_METRICS
        for controller in controllers
        for plant in ("sim", "proxy")
        if metric != "gate_open_fraction" or controller_entry(controller).has_gate
    }


TABLE3_COLUMNS: dict[str, Source] = tracking_columns("sim", tabled_controllers())
"""Columns of ``table3.csv`` [%] for the paper's controllers, and where each comes from."""

TABLE4_COLUMNS: dict[str, Source] = force_columns(tabled_controllers())
"""Columns of ``table4.csv`` for the paper's controllers, and where each comes from."""


@dataclass(frozen=True)
class ResultTable:
    """A table as written (``values``: object, profile, the value columns, then their
    ``_ci95`` columns) and the number of finite trials behind each value (``counts``:
    object, profile, then the value columns holding integers)."""

    values: pd.DataFrame
    counts: pd.DataFrame

    @property
    def value_columns(self) -> list[str]:
        return [c for c in self.counts.columns if c not in ("object", "profile")]


def ci95_halfwidth(values: np.ndarray | pd.Series) -> float:
    """Half-width of the 95 % confidence interval of the mean of the finite ``values``
    (Student t, n − 1 degrees of freedom); NaN for fewer than two finite values."""
    finite = np.asarray(values, dtype=float)
    finite = finite[np.isfinite(finite)]
    n = finite.size
    if n < 2:
        return math.nan
    t = float(stats.t.ppf(0.5 + 0.5 * CONFIDENCE, n - 1))
    return t * float(np.std(finite, ddof=1)) / math.sqrt(n)


def _finite_mean(values: np.ndarray) -> float:
    finite = values[np.isfinite(values)]
    return float(finite.mean()) if finite.size else math.nan


def ordered_names(names: pd.Series, known: tuple[str, ...]) -> list[str]:
    """The distinct ``names``: the ``known`` ones in that order, then the others sorted."""
    present = set(names)
    return [n for n in known if n in present] + sorted(present - set(known))


def cells(trials: pd.DataFrame) -> list[tuple[str, str]]:
    """The (object, profile) pairs present in ``trials``, cube before wedge and constant,
    trapezoid, chirp in the paper's order (other names after, sorted)."""
    present = set(zip(trials["object"], trials["profile"], strict=True))
    return [
        (obj, profile)
        for obj in ordered_names(trials["object"], OBJECT_ORDER)
        for profile in ordered_names(trials["profile"], PROFILE_ORDER)
        if (obj, profile) in present
    ]


def summarise(trials: pd.DataFrame, columns: dict[str, Source]) -> ResultTable:
    """One row per (object, profile) of ``trials`` (the columns of ``trials.csv``): the
    mean, 95 % CI half-width and finite count of each of ``columns``. A source with no rows
    (say no ``proxy`` trials were run) gives NaN and a count of 0."""
    groups = trials.groupby(["object", "profile", "plant", "controller"], sort=False)
    empty = np.array([], dtype=float)
    rows, counts = [], []
    for obj, profile in cells(trials):
        row: dict[str, object] = {"object": obj, "profile": profile}
        count: dict[str, object] = dict(row)
        intervals = {}
        for name, (metric, plant, controller) in columns.items():
            key = (obj, profile, plant, controller)
            present = key in groups.groups and metric in trials.columns  # older files lack some
            values = groups.get_group(key)[metric].to_numpy(float) if present else empty
            row[name] = _finite_mean(values)
            intervals[f"{name}_ci95"] = ci95_halfwidth(values)
            count[name] = int(np.isfinite(values).sum())
        rows.append(row | intervals)
        counts.append(count)
    return ResultTable(values=pd.DataFrame(rows), counts=pd.DataFrame(counts))


def _mujoco_columns(trials: pd.DataFrame, columns: dict[str, Source]) -> dict[str, Source]:
    """``columns`` for the ``mujoco`` plant (named ``<column>_mujoco``, sim's sources with
    the plant swapped) when ``trials`` has mujoco rows, else none: tables of a sim/proxy
    evaluation keep their columns."""
    if not (trials["plant"] == "mujoco").any():
        return {}
    sim = {name: source for name, source in columns.items() if source[1] == "sim"}
    return {
        f"{name.removesuffix('_sim')}_mujoco": (metric, "mujoco", controller)
        for name, (metric, _, controller) in sim.items()
    }


def table3(trials: pd.DataFrame) -> ResultTable:
    """The paper's Table III from ``trials``: translation and angle error [%] of each of
    :func:`tabled_controllers` (PD-only, feedback, RL-assisted, …), ``sim`` plant (and
    ``mujoco``, ``…_mujoco`` columns, if it was run)."""
    columns = tracking_columns("sim", tabled_controllers(trials))
    return summarise(trials, columns | _mujoco_columns(trials, columns))


def table3_proxy(trials: pd.DataFrame) -> ResultTable:
    """Table III's errors on the ``proxy`` plant (``table3_proxy.csv`` [%])."""
    return summarise(trials, tracking_columns("proxy", tabled_controllers(trials)))


def behaviour_table(trials: pd.DataFrame) -> ResultTable:
    """Slip, contact-loss and gate-open shares per cell: :func:`behaviour_columns`."""
    return summarise(trials, behaviour_columns(tabled_controllers(trials)))


def table4(trials: pd.DataFrame) -> ResultTable:
    """The paper's Table IV from ``trials``: force error [N] and torque error [N·m] of each
    of :func:`tabled_controllers`, ``sim`` and ``proxy`` plants (and ``mujoco`` if it was
    run)."""
    columns = force_columns(tabled_controllers(trials))
    return summarise(trials, columns | _mujoco_columns(trials, columns))
