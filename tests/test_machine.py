"""pushctl.machine names the kind of machine a run's bytes belong to (the manifest of
make reproduce-tables carries it)."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from pushctl.machine import blas_kernels, machine_description


def test_the_kernels_are_openblas_own_name_and_follow_its_coretype_switch() -> None:
    """The name comes from OpenBLAS itself: forcing its kernels with OPENBLAS_CORETYPE
    (read when numpy loads it) changes what it reports."""
    here = blas_kernels()
    assert here and " " not in here
    if here == "unknown":
        pytest.skip("this numpy brings no OpenBLAS that names its kernels")
    probe = "from pushctl.machine import blas_kernels; print(blas_kernels())"
    env = {**os.environ, "OPENBLAS_CORETYPE": "Sandybridge"}
    forced = subprocess.run(
        [sys.executable, "-c", probe], capture_output=True, text=True, env=env, timeout=120
    )
    assert forced.returncode == 0, forced.stderr
    assert forced.stdout.strip() == "Sandybridge"


def test_the_description_names_the_cpu_the_cores_and_the_kernels() -> None:
    line = machine_description()
    assert f"runs its {blas_kernels()} kernels" in line
    assert " cores; " in line and "\n" not in line
