"""pushctl.machine names the kind of machine a run's bytes belong to (the manifest of
make reproduce-tables carries it), and pins OpenBLAS's Haswell kernels on every x86-64 CPU
with AVX2 and FMA, so that a push ends in the same bits with and without AVX-512."""

from __future__ import annotations

import os
import platform
import subprocess
import sys
from pathlib import Path

import pytest

from pushctl.machine import (
    PINNED_KERNELS,
    blas_kernels,
    cpu_flags,
    kernels_to_pin,
    machine_description,
)


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


_PINNABLE = kernels_to_pin(platform.machine(), cpu_flags()) is not None


def _kernels_in_a_fresh_process(code: str, **env: str) -> str:
    clean = {k: v for k, v in os.environ.items() if k != "OPENBLAS_CORETYPE"}
    done = subprocess.run(
        [sys.executable, "-c", f"{code}; from pushctl.machine import blas_kernels; "
         "print(blas_kernels())"],
        capture_output=True, text=True, env={**clean, **env}, timeout=300,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    return done.stdout.strip()


def test_only_an_x86_64_cpu_with_avx2_and_fma_is_pinned() -> None:
    assert kernels_to_pin("x86_64", frozenset({"sse2", "avx2", "fma", "avx512f"})) == "Haswell"
    assert kernels_to_pin("AMD64", frozenset({"avx2", "fma"})) == "Haswell"
    assert kernels_to_pin("x86_64", frozenset({"sse2", "avx"})) is None  # would crash
    assert kernels_to_pin("aarch64", frozenset({"avx2", "fma"})) is None


def test_cpu_flags_reads_the_first_processor_and_nothing_where_there_is_no_file(
    tmp_path: Path,
) -> None:
    info = tmp_path / "cpuinfo"
    info.write_text("processor\t: 0\nflags\t\t: fpu avx2 fma\n\nprocessor\t: 1\nflags\t: fpu\n")
    assert cpu_flags(info) == frozenset({"fpu", "avx2", "fma"})
    assert cpu_flags(tmp_path / "missing") == frozenset()


@pytest.mark.skipif(not _PINNABLE or blas_kernels() == "unknown", reason="no x86-64 AVX2 CPU")
def test_importing_pushctl_first_runs_the_pinned_kernels_here_and_in_the_tests() -> None:
    assert blas_kernels() == PINNED_KERNELS  # this process: tests/conftest.py imports pushctl
    assert _kernels_in_a_fresh_process("import pushctl") == PINNED_KERNELS
    # a kernel family the user asks for is kept
    assert _kernels_in_a_fresh_process("import pushctl", OPENBLAS_CORETYPE="Sandybridge") == (
        "Sandybridge"
    )


def test_numpy_loaded_first_is_left_as_it_is() -> None:
    code = (
        "import os, numpy, pushctl; from pushctl.machine import pin_blas_kernels as pin; "
        "print(pin(), os.environ.get('OPENBLAS_CORETYPE'))"
    )
    done = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True, text=True, timeout=300,
        env={k: v for k, v in os.environ.items() if k != "OPENBLAS_CORETYPE"},
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["None", "None"]


@pytest.mark.skipif(not _PINNABLE or blas_kernels() == "unknown", reason="no x86-64 AVX2 CPU")
def test_ray_workers_run_the_drivers_kernels(ray_local) -> None:
    import ray

    @ray.remote
    def kernels() -> str:
        from pushctl.machine import blas_kernels

        return blas_kernels()

    assert ray.get(kernels.remote()) == PINNED_KERNELS
