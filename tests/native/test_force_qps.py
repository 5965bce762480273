"""The force distribution's QPs through the compiled library (pushctl.native) against the
same QPs through ProxSuite's Python bindings, to the bit."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np

import pushctl.planning.forces as forces
from pushctl import native
from pushctl.objects import make_object
from pushctl.planning import make_plan


def _captured_solves(monkeypatch) -> list[tuple[forces._StepQP, np.ndarray]]:
    """Every (QP, wrenches) the force distribution of a few plans solved (the offset
    search's and the final ones), for cube and wedge, three profiles."""
    captured: list[tuple[forces._StepQP, np.ndarray]] = []
    solve = forces._StepQP.solve

    def record(self, wrenches):
        captured.append((self, wrenches.copy()))
        return solve(self, wrenches)

    monkeypatch.setattr(forces._StepQP, "solve", record)
    for name, goal in (("cube", (0.62, 0.03, 0.5)), ("wedge", (0.6, -0.02, -0.4))):
        for profile in ("trapezoid", "chirp", "constant"):
            make_plan(make_object(name), goal, profile=profile)
    monkeypatch.setattr(forces._StepQP, "solve", solve)
    return captured


def _fresh(qp: forces._StepQP) -> forces._StepQP:
    """A new QP of the same offset (a solve warm-starts from its QP's previous solve)."""
    fresh = object.__new__(forces._StepQP)
    fresh.__dict__.update(qp.__dict__)
    fresh._qp = None
    return fresh


def _through_bindings(qp: forces._StepQP, wrenches: np.ndarray):
    qp._qp = qp._make_qp()  # a QP object of its own: solve() keeps to the bindings
    return qp.solve(wrenches)


def test_plans_force_qps_match_the_bindings_bit_for_bit(monkeypatch):
    captured = _captured_solves(monkeypatch)
    assert len(captured) > 50
    for qp, wrenches in captured:
        compiled = _fresh(qp).solve(wrenches)
        bound = _through_bindings(_fresh(qp), wrenches)
        for x, y in zip(compiled, bound, strict=True):
            assert x.tobytes() == y.tobytes()


def test_unsolved_warm_solves_are_solved_again_as_the_bindings_do(monkeypatch):
    """With a tolerance of 0 most warm solves end unsolved: each is solved again
    from scratch (NaN where that fails too), in the same way on both paths."""
    qp, wrenches = _captured_solves(monkeypatch)[-1]
    wrenches = wrenches[:300]
    monkeypatch.setattr(forces, "_QP_TOLERANCE", 0.0)
    monkeypatch.setattr(forces, "_QP_MAX_ITER", 3)
    retried: list[int] = []
    cold = forces._StepQP._solve_cold

    def counted(self, gradient):
        retried.append(1)
        return cold(self, gradient)

    monkeypatch.setattr(forces._StepQP, "_solve_cold", counted)
    compiled = _fresh(qp).solve(wrenches)
    compiled_retries = len(retried)
    bound = _through_bindings(_fresh(qp), wrenches)
    assert compiled_retries > 100 and len(retried) == 2 * compiled_retries
    for x, y in zip(compiled, bound, strict=True):
        assert x.tobytes() == y.tobytes()


def test_the_compiled_path_runs_where_the_library_is_in_use(monkeypatch):
    qp, wrenches = _captured_solves(monkeypatch)[0]
    calls: list[int] = []
    library = native.library()
    compiled_solve = library.pushctl_force_qps

    class Counting:
        def __getattr__(self, name):
            return getattr(library, name)

        def pushctl_force_qps(self, *args):
            calls.append(1)
            return compiled_solve(*args)

    monkeypatch.setattr(native, "library", lambda: Counting())
    _fresh(qp).solve(wrenches)
    assert calls == [1]


def test_pushctl_native_0_keeps_to_the_bindings():
    """PUSHCTL_NATIVE=0 is read once per process: a fresh process with it reports the
    bindings."""
    done = subprocess.run(
        [sys.executable, "-c", "from pushctl import native; print(native.status())"],
        capture_output=True,
        text=True,
        env={**os.environ, "PUSHCTL_NATIVE": "0"},
        check=True,
    )
    assert "PUSHCTL_NATIVE=0" in done.stdout
