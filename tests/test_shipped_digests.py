"""The shipped ``results/`` stay as ``make reproduce-tables`` made them, and the code still
makes them: every shipped file's sha256 against ``tests/data/shipped_digests.json``, and a
few training episodes of the ``paper`` preset against the digest recorded with the shipped
code (the short evaluation's digest is checked in tests/evaluation/test_shipped_trials.py,
which runs it). After a change meant to move results, ``make reproduce-tables`` and then
``make digests`` record them again (docs/developing.md)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from shipped_digests import MANIFEST, UNPINNED, shipped_files, training_digest

from pushctl.machine import PINNED_KERNELS, blas_kernels

RECORDED = json.loads(MANIFEST.read_text())


def test_every_shipped_file_has_its_recorded_bytes() -> None:
    shipped = shipped_files()
    assert len(shipped) >= 25  # tables, figures, trials, every seed's policy and curves
    changed = sorted(name for name in shipped if shipped[name] != RECORDED["results"].get(name))
    assert changed == []
    assert sorted(RECORDED["results"]) == sorted(shipped)  # none added, none removed


def test_the_unpinned_files_are_timings_and_the_manifest_only() -> None:
    assert UNPINNED == ("bench.csv", "provenance.md")


@pytest.mark.skipif(blas_kernels() != PINNED_KERNELS, reason="not the shipped kernels")
def test_a_few_training_episodes_give_the_recorded_digest(tmp_path: Path) -> None:
    """Two rounds of the ``paper`` preset's episodes in this process (the warm-up's law,
    DDPG updates, a validation): the curves and the actor's weights, to the bit."""
    assert training_digest(tmp_path / "run") == RECORDED["training"]
