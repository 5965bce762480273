"""The search of the ``feedback`` law's catch-up phase (pushctl/defaults/feedback_gains.toml)
on the tuning stream, over the ``sim`` and ``proxy`` plants together.

The space (:data:`SPACE`), around the steady gains of ``pushctl/defaults/feedback_gains.toml``:
the phase's length ``catchup_time`` [s], its gains ``catchup_k`` [1/s] (``catchup_k_i`` is
the steady k_i), one relaxed cap for both ``catchup_lateral_ratio`` and
``catchup_turn_ratio`` [-], the load every prong must carry for the caps to be relaxed,
``catchup_force`` [N], and the law's own gate after the phase, ``gate_threshold`` [m] (the
phase's own gate is open, as in the hand-written catch-up that motivated it). The candidates:
the steady law itself (``steady``), the hand-written catch-up (``hand``: 3 s, k = 3 /s, caps
0.15, unguarded, gate open), the same guarded at 0.2 N (``hand_guarded``), and
:data:`N_RANDOM` points drawn from the space with ``numpy.random.default_rng(SPACE_SEED)``.

The pushes: per object × profile (case c = 0 … 5, :data:`~pushctl.objects.OBJECT_NAMES` ×
:data:`~pushctl.planning.PROFILE_NAMES`) the tuning stream's scenario seeds
``c · PER_CASE + i``, i < ``per_case`` (``tune-feedback``'s seeds at ``--per-case 50``), on
each plant; each push is reset once and every candidate pushes a copy of it. The objective:
the mean over every push of both plants of translation error % + angle error % (angle over
the pushes that turn), as ``tune-feedback``'s; a failed push (a non-finite state) makes it
infinite. Stage ``coarse`` scores every candidate on ``per_case`` = 10; stage ``fine``
scores the best :data:`N_FINE` of the coarse stage (and ``steady``) on all 50; a round of
stage ``refine`` scores, on all 50, the neighbours (:func:`neighbours`) of the best
candidate scored on all 50 so far (:func:`refine_centre`): rounds repeated until the best
is a centre whose neighbours are all scored are a greedy coordinate search.

Rows go to ``runs/law_search/<plant>.csv`` as each push ends (one row per candidate and
push); a run skips the rows its file already holds, so a killed run resumes. The fine stage
ranks the candidates on the coarse pushes only (i < 10), so a resumed run ranks them alike.
Run (the coarse stage on both plants before the fine stage on either)::

    python -m studies.catchup_search run sim coarse
    python -m studies.catchup_search run sim fine
    python -m studies.catchup_search refine sim
    python -m studies.catchup_search summary [PER_CASE]
"""

from __future__ import annotations

import copy
import csv
import itertools
import math
import re
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from pushctl.control.feedback_gains import (
    DEFAULT_FEEDBACK_FILE,
    STEADY_FEEDBACK_FILE,
    FeedbackGains,
    feedback_table,
    load_feedback_gains,
)
from pushctl.controllers.feedback import feedback_config
from pushctl.episode.metrics import compute_metrics
from pushctl.errors import PushctlError
from pushctl.evaluation.tune_feedback import tuning_env
from pushctl.files.provenance import write_atomic
from pushctl.objects import OBJECT_NAMES
from pushctl.planning import PROFILE_NAMES
from pushctl.rl.policy import finish_with_policy
from pushctl.task.feedback_actor import FeedbackActor

SPACE = {
    "catchup_time": (2.0, 3.0, 5.0),
    "catchup_k": (2.0, 3.0, 5.0),
    "cap": (0.1, 0.15, 0.25),
    "catchup_force": (0.05, 0.2, 0.4),
    "gate_threshold": (0.0, 1.5e-4),
}
"""The catch-up's parameters and the values drawn from (units in the module doc)."""
SPACE_SEED = 57
N_RANDOM = 12
PER_CASE = 50
COARSE_PER_CASE = 10
N_FINE = 4
COLUMNS = (
    "candidate",
    "plant",
    "object",
    "profile",
    "scenario_seed",
    "translation_error_pct",
    "angle_error_pct",
    "failed",
)
RUNS = Path("runs/law_search")


Point = tuple[float, float, float, float, float, float | None]
"""(catchup_time, catchup_k, cap, catchup_force, gate_threshold, turn cap or None: the
lateral cap's value)."""


def point_name(point: Point) -> str:
    time, k, cap, force, gate, turn = point
    name = f"T{time:g}_k{k:g}_c{cap:g}_F{force:g}_g{gate * 1e3:g}"
    return name if turn is None else f"{name}_w{turn:g}"


def point_gains(steady: FeedbackGains, point: Point) -> FeedbackGains:
    time, k, cap, force, gate, turn = point
    return replace(
        steady,
        catchup_time=time,
        catchup_k=k,
        catchup_k_i=steady.k_i,
        catchup_lateral_ratio=cap,
        catchup_turn_ratio=cap if turn is None else turn,
        catchup_force=force,
        catchup_gate=0.0,
        gate_threshold=gate,
    )


def points() -> dict[str, Point]:
    """The coarse stage's points by name (module doc), in a fixed order."""
    named: dict[str, Point] = {
        "hand": (3.0, 3.0, 0.15, 0.05, 0.0, None),
        "hand_guarded": (3.0, 3.0, 0.15, 0.2, 0.0, None),
    }
    rng = np.random.default_rng(SPACE_SEED)
    grid = list(itertools.product(*SPACE.values()))
    for index in rng.choice(len(grid), size=N_RANDOM, replace=False):
        time, k, cap, force, gate = grid[int(index)]
        named[point_name((time, k, cap, force, gate, None))] = (time, k, cap, force, gate, None)
    return named


def neighbours(centre: Point) -> dict[str, Point]:
    """The refinement around ``centre``: one parameter moved at a time (the time, k, the
    caps and the force times 0.75 and 1.5 (k: 0.7 and 1.4); the gate toggled between 0 and
    0.15 mm; the turn cap left at the steady 0.05)."""
    time, k, cap, force, gate, turn = centre
    moved: list[Point] = []
    for factor in (0.75, 1.5):
        moved.append((time * factor, k, cap, force, gate, turn))
    for factor in (0.7, 1.4):
        moved.append((time, round(k * factor, 3), cap, force, gate, turn))
    for factor in (0.7, 1.4):
        moved.append((time, k, round(cap * factor, 4), force, gate, turn))
    for factor in (0.75, 1.5):
        moved.append((time, k, cap, round(force * factor, 3), gate, turn))
    moved.append((time, k, cap, force, 0.0 if gate > 0.0 else 1.5e-4, turn))
    moved.append((time, k, cap, force, gate, 0.05))
    return {point_name(p): p for p in moved}


def candidates(steady: FeedbackGains | None = None) -> dict[str, FeedbackGains]:
    """The coarse stage's candidates: ``steady`` and :func:`points`, in a fixed order."""
    steady = steady or load_feedback_gains(STEADY_FEEDBACK_FILE)
    return {"steady": steady} | {n: point_gains(steady, p) for n, p in points().items()}


NAME = re.compile(
    r"T(?P<time>[\d.]+)_k(?P<k>[\d.]+)_c(?P<cap>[\d.]+)_F(?P<force>[\d.]+)"
    r"_g(?P<gate>[\d.]+)(_w(?P<turn>[\d.]+))?"
)


def parse_name(name: str) -> Point | None:
    """The point a :func:`point_name` names (None: a named candidate, or none at all)."""
    found = NAME.fullmatch(name)
    if found is None:
        return None
    turn = found["turn"]
    values = (float(found[key]) for key in ("time", "k", "cap", "force"))
    return (*values, float(found["gate"]) * 1e-3, None if turn is None else float(turn))


def refine_centre() -> Point:
    """The best candidate other than ``steady`` scored on all :data:`PER_CASE` pushes of
    both plants so far (the fine stage's, then the refinement's)."""
    found = summary([RUNS / "sim.csv", RUNS / "proxy.csv"], PER_CASE)
    full = 2 * len(OBJECT_NAMES) * len(PROFILE_NAMES) * PER_CASE
    named = points()
    named |= {n: p for n in found if (p := parse_name(n)) is not None and n not in named}
    ranked = [n for n in named if n in found and found[n]["pushes"] == full]
    return named[min(ranked, key=lambda n: found[n]["objective"])]


def all_candidates() -> dict[str, FeedbackGains]:
    """Every candidate the stages may push: the coarse stage's, every point the rows name,
    and the neighbours of :func:`refine_centre` once the fine stage is done."""
    steady = load_feedback_gains(STEADY_FEEDBACK_FILE)
    pool = candidates(steady)
    try:
        found = summary([RUNS / "sim.csv", RUNS / "proxy.csv"], PER_CASE)
        centre = refine_centre()
    except (ValueError, FileNotFoundError, KeyError):  # no fine stage yet
        return pool
    named = {n: p for n in found if (p := parse_name(n)) is not None} | neighbours(centre)
    return pool | {n: point_gains(steady, p) for n, p in named.items() if n not in pool}


def _done(path: Path) -> set[tuple[str, str, str, int]]:
    if not path.is_file():
        return set()
    with path.open() as handle:
        return {
            (row["candidate"], row["object"], row["profile"], int(row["scenario_seed"]))
            for row in csv.DictReader(handle)
        }


def run(plant: str, names: list[str], per_case: int, out: Path) -> None:
    """Push every (case, seed < per_case) with each of ``names`` on ``plant``; append rows."""
    pool = all_candidates()
    done = _done(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fresh = not out.is_file()
    env = tuning_env(20.0, plant=plant)
    with out.open("a", newline="") as handle:
        writer = csv.writer(handle)
        if fresh:
            writer.writerow(COLUMNS)
        for case, (object_name, profile) in enumerate(
            itertools.product(OBJECT_NAMES, PROFILE_NAMES)
        ):
            for i in range(per_case):
                seed = case * PER_CASE + i
                todo = [n for n in names if (n, object_name, profile, seed) not in done]
                if not todo:
                    continue
                options = {"object": object_name, "profile": profile, "scenario_seed": seed}
                env.reset(options=options)
                for name in todo:
                    gains = pool[name]
                    push = copy.deepcopy(env)
                    push.config = feedback_config(push.config, gains)
                    try:
                        finish_with_policy(push, FeedbackActor(push, gains))
                        metrics = compute_metrics(push.episode.trace())
                        row = (metrics.translation_error_pct, metrics.angle_error_pct, 0)
                    except PushctlError:
                        row = (math.nan, math.nan, 1)
                    writer.writerow((name, plant, object_name, profile, seed, *row))
                    handle.flush()


def summary(paths: list[Path], per_case: int = PER_CASE) -> dict[str, dict[str, float]]:
    """Per candidate: pushes, failures, objective (and the steady law's on the same pushes),
    and per (plant, cell) its translation and angle ratios to the steady law's means, over
    the pushes with i < ``per_case`` it has in common with ``steady``."""
    import pandas as pd

    rows = pd.concat([pd.read_csv(path) for path in paths if path.is_file()])
    rows = rows[rows.scenario_seed % PER_CASE < per_case]
    key = ["plant", "object", "profile", "scenario_seed"]
    result: dict[str, dict[str, float]] = {}
    steady = rows[rows.candidate == "steady"].set_index(key)
    for name, group in rows.groupby("candidate", sort=False):
        group = group.set_index(key)
        common = group.index.intersection(steady.index)
        mine, base = group.loc[common], steady.loc[common]
        failed = mine.failed.sum()
        objective = mine.translation_error_pct.mean() + mine.angle_error_pct.mean()
        entry = {
            "pushes": float(len(mine)),
            "failed": float(failed),
            "objective": math.inf if failed else float(objective),
            "steady_objective": float(
                base.translation_error_pct.mean() + base.angle_error_pct.mean()
            ),
        }
        for (plant, obj, profile), cell in mine.groupby(level=[0, 1, 2]):
            ref = base.loc[cell.index]
            t = cell.translation_error_pct.mean() / ref.translation_error_pct.mean()
            a = cell.angle_error_pct.mean() / ref.angle_error_pct.mean()
            entry[f"{plant}/{obj}/{profile}"] = (round(float(t), 3), round(float(a), 3))
        result[str(name)] = entry
    return result


def catchup_toml(name: str, found: dict[str, dict[str, float]], command: str) -> str:
    """The text of pushctl/defaults/feedback_gains.toml: candidate ``name``'s gains and a
    ``[search]`` record of ``found`` (:func:`summary`): its figures and every candidate's
    objective beside the steady law's."""
    gains = all_candidates()[name]
    entry = found.get(name, {})
    record: dict[str, object] = {
        "procedure": "seeded random search, coarse, fine, then one-at-a-time refinement "
        "(studies.catchup_search)",
        "objective": "mean over the pushes of both plants of translation error % + angle error %",
        "stream": "tuning",
        "plants": ["sim", "proxy"],
        "objects": list(OBJECT_NAMES),
        "profiles": list(PROFILE_NAMES),
        "space": [f"{key} = {list(values)}" for key, values in SPACE.items()],
        "space_seed": SPACE_SEED,
        "candidate": name,
        "pushes": entry.get("pushes", 0.0),
        "objective_value": entry.get("objective", math.nan),
        "steady_objective": entry.get("steady_objective", math.nan),
        "ratios_to_steady_translation_angle": [
            f"{cell} {value[0]} {value[1]}"
            for cell, value in entry.items()
            if isinstance(value, tuple)
        ],
        "candidates_name_pushes_objective_steady": [
            f"{other} {int(e['pushes'])} {e['objective']:.4f} {e['steady_objective']:.4f}"
            for other, e in found.items()
        ],
    }
    lines = [f"# made by: {command}"]
    lines += [
        "# The feedback law with its catch-up phase (pushctl/control/feedback_gains.py): the",
        "# steady gains of feedback_gains_v1.toml after the push's first catchup_time seconds.",
        "",
        *feedback_table(gains),
        "",
        "[search]",
    ]
    lines += [f"{key} = {_toml(value)}" for key, value in record.items()]
    return "\n".join(lines) + "\n"


def _toml(value: object) -> str:
    if isinstance(value, str):
        return '"' + value.replace('"', "'") + '"'
    if isinstance(value, list):
        return "[" + ", ".join(_toml(item) for item in value) + "]"
    if isinstance(value, float) and not math.isfinite(value):
        return "nan" if math.isnan(value) else "inf"
    return repr(value)


def main(argv: list[str]) -> None:
    """``run PLANT coarse|fine``, ``refine PLANT``, ``summary [PER_CASE]`` or
    ``write NAME [PER_CASE]``."""
    if argv[0] == "write":
        per_case = int(argv[2]) if len(argv) > 2 else PER_CASE
        found = summary([RUNS / "sim.csv", RUNS / "proxy.csv"], per_case)
        command = "python -m studies.catchup_search " + " ".join(argv)
        text = catchup_toml(argv[1], found, command)
        write_atomic(DEFAULT_FEEDBACK_FILE, lambda tmp: Path(tmp).write_text(text))
        return
    if argv[0] == "run":
        plant, stage = argv[1], argv[2]
        out = RUNS / f"{plant}.csv"
        if stage == "coarse":
            run(plant, list(candidates()), COARSE_PER_CASE, out)
        else:
            found = summary([RUNS / "sim.csv", RUNS / "proxy.csv"], COARSE_PER_CASE)
            ranked = sorted(
                (n for n in found if n != "steady"), key=lambda n: found[n]["objective"]
            )
            run(plant, ["steady", *ranked[:N_FINE]], PER_CASE, out)
    elif argv[0] == "refine":  # one round: the neighbours of the best so far
        plant = argv[1]
        run(plant, list(neighbours(refine_centre())), PER_CASE, RUNS / f"{plant}.csv")
    else:
        per_case = int(argv[1]) if len(argv) > 1 else PER_CASE
        found = summary([RUNS / "sim.csv", RUNS / "proxy.csv"], per_case)
        for name, entry in sorted(found.items(), key=lambda item: item[1]["objective"]):
            print(name, entry)


if __name__ == "__main__":
    main(sys.argv[1:])
