"""The library's loader: what it refuses, and that a library that does not load leaves the
process on the Python bindings with a one-line reason (each case in a fresh process: the
loader decides once per process)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from pushctl import native

_PROBE = """
import json, sys
from pathlib import Path
import pushctl.native as native
native.LIBRARY = Path(sys.argv[1])
native.STAMP = native.LIBRARY.with_suffix(".json")
if sys.argv[2] == "stamp":
    native.STAMP.write_text(json.dumps(native.expected_stamp()))
from pushctl.arm import load_arm
import numpy as np
arm = load_arm()
arm.compute(arm.q_ready, np.zeros(arm.nv))  # runs, through the bindings
print(native.available(), native.status())
"""


def _probe(tmp_path: Path, content: bytes, stamp: str) -> str:
    library = tmp_path / "libpushctl_native.so"
    library.write_bytes(content)
    if stamp == "other":
        library.with_suffix(".json").write_text(json.dumps({"pinocchio": "0.0"}))
    done = subprocess.run(
        [sys.executable, "-c", _PROBE, str(library), stamp],
        capture_output=True, text=True, check=True, env={**os.environ, "PUSHCTL_NATIVE": "1"},
    )  # fmt: skip
    return done.stdout.strip()


def test_a_library_that_does_not_load_leaves_the_bindings_with_a_reason(tmp_path):
    out = _probe(tmp_path, b"not a shared object", "stamp")
    assert out.startswith("False") and "did not load" in out and "rebuild" in out


def test_a_library_built_for_other_versions_is_refused(tmp_path):
    out = _probe(tmp_path, native.LIBRARY.read_bytes(), "other")
    assert out.startswith("False") and "other versions or sources" in out
