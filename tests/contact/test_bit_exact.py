"""Bit-exact runs: the cold MLCP path's compiled pivoting against the numpy reference, a
slipping push repeated in one process with unrelated allocations between, and a short
``pushctl evaluate`` in two fresh processes writing the same bytes."""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from test_contact_kernels import random_mlcp

import pushctl.contact.step_solver as solver_module  # where the step calls slip_step
from pushctl.contact.active_set import evaluate, labels_at, solve_labels
from pushctl.contact.compiled.pivoting import _solve_labels, pivot_solve
from pushctl.contact.mlcp import _box_problem, _fixed_point
from pushctl.contact.mlcp_checks import validated_arrays
from pushctl.machine.proxqp_build import PORTABLE_MODULE, proxqp, proxsuite
from pushctl.task.env import PushEnv
from pushctl.task.env_config import EnvConfig


@pytest.mark.parametrize("singular", [False, True])
def test_compiled_pivoting_matches_the_numpy_reference(singular: bool) -> None:
    rng = np.random.default_rng(3)
    checked = verified = 0
    for _ in range(150):
        args = random_mlcp(rng, int(rng.integers(1, 4)), int(rng.integers(0, 5)), singular)
        D, b, lo, hi, findex, mu = validated_arrays(*args, 1e-9)
        prob = _box_problem(D, b, lo, hi, findex, mu, 1e-9)
        labels = labels_at(prob, rng.normal(scale=0.5, size=len(b)))
        work = np.full((len(b), len(b)), np.nan)  # whatever a previous solve left there
        compiled = _solve_labels(prob.D, prob.b, prob.lo, prob.hi, prob.mu, prob.fi, labels, work)
        reference = solve_labels(prob, labels)
        if np.all(np.isfinite(reference)) and np.abs(reference).max() < 1e6:
            np.testing.assert_allclose(compiled, reference, rtol=1e-7, atol=1e-9)
            checked += 1
        p, w, residual, ok, _ = pivot_solve(
            prob.D, prob.b, prob.lo, prob.hi, prob.mu, prob.fi, labels, 1e-9, 30
        )
        # Its residual is the reference's natural map at its p, and "verified" means it.
        assert residual == pytest.approx(evaluate(prob, p).residual, rel=1e-9, abs=1e-13)
        np.testing.assert_allclose(w, D @ p + b, atol=1e-12)
        assert ok == (residual <= 1e-9)
        verified += ok
    assert checked > 100 and verified > 100


def _junk(rng: np.random.Generator) -> list:
    """Unrelated allocations: numpy arrays of many sizes and throw-away ProxQP problems
    (whose workspaces are what moved ProxQP's last bits before)."""
    kept = [np.empty(int(rng.integers(1, 4000))) for _ in range(int(rng.integers(50, 300)))]
    for _ in range(int(rng.integers(1, 10))):
        n = int(rng.integers(2, 14))
        qp = proxqp.dense.QP(n, 0, 0, True)
        qp.init(np.eye(n), np.ones(n), None, None, None, None, None, -np.ones(n), np.ones(n))
        qp.solve()
        kept.append(qp)
    return kept[:: int(rng.integers(1, 4))]  # free some, keep the others alive


def test_the_proxqp_fallback_does_not_depend_on_the_heap() -> None:
    """The ProxQP fixed point (the cold path's fallback) gives the same iterates, to the
    bit, with unrelated allocations between (with a fresh QP per solve and ProxSuite's AVX-512
    build it did not)."""
    rng = np.random.default_rng(2)
    instances = []
    for _ in range(10):
        args = random_mlcp(rng, 3, 6, singular=True)
        D, b, lo, hi, findex, mu = validated_arrays(*args, 1e-9)
        prob = _box_problem(D, b, lo, hi, findex, mu, 1e-9)
        instances.append((prob, rng.normal(scale=0.1, size=len(b))))
    seen: list[set[bytes]] = [set() for _ in instances]
    held = []
    for _ in range(6):
        for k, (prob, start) in enumerate(instances):
            iterates = [cand.p.tobytes() for cand, _ in _fixed_point(prob, start, 50, 1.0)]
            seen[k].add(b"".join(iterates))
            held += _junk(rng)
    assert all(len(answers) == 1 for answers in seen)


def test_proxqp_is_the_portable_build() -> None:
    assert proxsuite._submodule.__name__ == PORTABLE_MODULE


def test_fresh_qps_answer_to_the_bit_wherever_their_memory_lies() -> None:
    """A fresh ProxQP problem per solve, with allocations between, gives one answer per
    problem. (With ProxSuite's AVX-512 build on this machine every one of these 20 problems
    had two or more answers among its 30 solves.)"""
    rng = np.random.default_rng(2)
    held = []
    for _ in range(20):
        D, b, lo, hi, _, _ = validated_arrays(*random_mlcp(rng, 3, 6, singular=True), 1e-9)
        answers = set()
        for _ in range(30):
            held.append(np.empty(int(rng.integers(1, 400))))
            qp = proxqp.dense.QP(len(b), 0, 0, True)
            qp.settings.eps_abs, qp.settings.eps_rel = 1e-11, 0.0
            qp.init(D, b, None, None, None, None, None, lo, hi)
            qp.solve()
            answers.add(np.array(qp.results.x).tobytes())
            held.append(qp)
        assert len(answers) == 1


def test_proxsuite_imported_before_pushctl_is_refused_saying_what_to_do() -> None:
    probe = "import proxsuite; print(proxsuite._submodule.__name__)"
    run = dict(capture_output=True, text=True, timeout=120)
    alone = subprocess.run([sys.executable, "-c", probe], **run)
    if alone.stdout.strip() == PORTABLE_MODULE:
        pytest.skip("this CPU has neither AVX2 nor AVX-512: proxsuite loads its portable build")
    code = "import proxsuite, pushctl.contact.mlcp"
    done = subprocess.run([sys.executable, "-c", code], **run)
    assert done.returncode != 0
    assert "ImportError: proxsuite was imported with its proxsuite.proxsuite_pywrap_" in (
        done.stderr
    )
    assert "import pushctl.machine.proxqp_build before proxsuite" in done.stderr


def _slipping_push(steps: int) -> tuple[str, int]:
    """Hash of every observation, reward and prong force of a push with random actions
    (the prongs slip: the cold MLCP path runs), and how many cold solves it made."""
    env = PushEnv(EnvConfig(duration=2.0, gate_threshold=0.0))
    rng = np.random.default_rng(0)
    obs, _ = env.reset(seed=4, options={"object": "wedge", "profile": "chirp"})
    digest = hashlib.sha256(obs.tobytes())
    cold = solver_module.slip_step.calls  # type: ignore[attr-defined]
    for _ in range(steps):
        action = rng.uniform(-1.0, 1.0, size=3).astype(np.float32)
        obs, reward, terminated, truncated, _ = env.step(action)
        digest.update(obs.tobytes())
        digest.update(np.float64(reward).tobytes())
        if terminated or truncated:
            break
    assert env.episode is not None
    digest.update(env.episode.trace().to_frame().to_numpy().tobytes())
    return digest.hexdigest(), solver_module.slip_step.calls - cold  # type: ignore[attr-defined]


def test_a_slipping_push_repeats_to_the_bit_with_allocations_between(monkeypatch) -> None:
    solve = solver_module.slip_step

    def counted(*args):
        outcome = solve(*args)
        counted.calls += outcome[7] > 0  # the kept solve pivoted: the cold path ran
        return outcome

    counted.calls = 0
    monkeypatch.setattr(solver_module, "slip_step", counted)
    rng = np.random.default_rng(1)
    first, cold = _slipping_push(150)
    assert cold >= 5, "the push never left the warm path: it tests nothing"
    held = _junk(rng)
    second, _ = _slipping_push(150)
    held += _junk(rng)
    third, _ = _slipping_push(150)
    assert first == second == third
    del held


def test_evaluate_in_two_fresh_processes_writes_the_same_bytes(tmp_path: Path) -> None:
    out = tmp_path / "evaluation"
    command = [sys.executable, "-m", "pushctl.cli", "evaluate", "--object", "wedge"]
    command += ["--profile", "chirp", "--trials", "1", "--controller", "pd", "--plant", "both"]
    command += ["--out", str(out), "--force"]
    files = []
    # different dict/set layouts (different heap histories); the second run without
    # pushctl's compiled library (pushctl/native: the bindings' bits, so the same bytes)
    for hash_seed, native in (("1", "1"), ("2", "0")):
        env = {**os.environ, "PYTHONHASHSEED": hash_seed, "PUSHCTL_NATIVE": native}
        done = subprocess.run(command, capture_output=True, text=True, env=env, timeout=300)
        assert done.returncode == 0, done.stderr
        files.append((out / "trials.csv").read_bytes() + (out / "steps.csv").read_bytes())
    assert files[0] == files[1]
