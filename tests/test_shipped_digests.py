"""The shipped ``results/`` stay as ``make reproduce-tables`` made them, and the code still
makes them: every shipped file's sha256 against ``tests/data/shipped_digests.json``, and a
few training episodes of the ``paper`` preset against the digest recorded with the shipped
code on a machine of this one's scope (``pushctl.machine.SCOPES``; skipped, saying what
differs, where none was recorded). On any machine, the same seed trains the same bytes
twice in one process and in a fresh one. (The short evaluation's digest is checked in
tests/evaluation/test_shipped_trials.py, which runs it.) After a change meant to move
results, ``make reproduce-tables`` and then ``make digests`` record them again
(docs/developing.md)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from shipped_digests import (
    MANIFEST,
    UNPINNED,
    recorded_for_this_machine,
    shipped_files,
    training_digest,
)

from pushctl.machine import SCOPES

RECORDED = json.loads(MANIFEST.read_text())


def test_every_shipped_file_has_its_recorded_bytes() -> None:
    shipped = shipped_files()
    assert len(shipped) >= 25  # tables, figures, trials, every seed's policy and curves
    changed = sorted(name for name in shipped if shipped[name] != RECORDED["results"].get(name))
    assert changed == []
    assert sorted(RECORDED["results"]) == sorted(shipped)  # none added, none removed


def test_the_unpinned_files_are_timings_and_the_manifest_only() -> None:
    assert UNPINNED == ("bench.csv", "provenance.md")


def test_every_recomputed_digest_names_the_scope_it_holds_on() -> None:
    for kind, fields in SCOPES.items():
        assert RECORDED[kind], f"no {kind} digest recorded"
        for entry in RECORDED[kind]:
            assert sorted(entry["scope"]) == sorted(fields)
            assert len(entry["digest"]) == 64


def test_a_few_training_episodes_give_the_recorded_digest(tmp_path: Path) -> None:
    """Two rounds of the ``paper`` preset's episodes in this process (the warm-up's law,
    DDPG updates, a validation): the curves and the actor's weights, to the bit, on a
    machine of the recorded scope."""
    recorded, why_not = recorded_for_this_machine("training")
    if recorded is None:
        pytest.skip(why_not)
    assert training_digest(tmp_path / "run") == recorded


_FRESH = """
import sys
from pathlib import Path
import pushctl
pushctl.reproducible()
sys.path.insert(0, sys.argv[1])
from shipped_digests import training_digest
print(training_digest(Path(sys.argv[2])))
"""


def test_one_seed_trains_the_same_bytes_twice_and_in_a_fresh_process(tmp_path: Path) -> None:
    """What holds on any machine: the short run's digest repeats in this process and in a
    fresh Python process (which pins the CPU code as the ``pushctl`` command does)."""
    first = training_digest(tmp_path / "first")
    assert training_digest(tmp_path / "second") == first
    env = {k: v for k, v in os.environ.items() if k != "PYTHONHASHSEED"}
    tests = str(Path(__file__).resolve().parent)
    fresh = subprocess.run(
        [sys.executable, "-c", _FRESH, tests, str(tmp_path / "fresh")],
        capture_output=True, text=True, env=env, timeout=600,
    )  # fmt: skip
    assert fresh.returncode == 0, fresh.stderr[-2000:]
    assert fresh.stdout.strip().splitlines()[-1] == first


def test_a_digest_of_another_scope_is_skipped_naming_what_differs(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import shipped_digests

    here = RECORDED["training"][0]["scope"]
    other = {**here, "cpu_vendor": "SomeOtherVendor", "torch": "0.0"}
    manifest = tmp_path / "digests.json"
    manifest.write_text(json.dumps({"training": [{"scope": other, "digest": "0" * 64}]}))
    monkeypatch.setattr(shipped_digests, "MANIFEST", manifest)
    digest, why_not = recorded_for_this_machine("training")
    assert digest is None
    assert "SomeOtherVendor recorded" in why_not and "0.0 recorded" in why_not
