"""pushctl.machine names the kind of machine a run's bytes belong to (the manifest of
make reproduce-tables carries it), and pins numpy's AVX2 code (OpenBLAS's Haswell kernels,
no AVX-512 loops) on every x86-64 CPU with AVX2 and FMA, so that a run writes the same bytes
with and without AVX-512."""

from __future__ import annotations

import os
import platform
import subprocess
import sys
from pathlib import Path

import pytest

from pushctl.machine import (
    NUMPY_AVX512_TARGETS,
    OLD_NUMPY_AVX512_TARGETS,
    PINNED_KERNELS,
    blas_kernels,
    code_to_pin,
    cpu_flags,
    cpu_level,
    machine_description,
    numpy_simd,
    scope_differences,
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
    assert f"runs its {blas_kernels()} kernels, its own loops up to {numpy_simd()}" in line
    assert " cores; " in line and "\n" not in line


_PINNABLE = bool(code_to_pin(platform.machine(), cpu_flags(), "2.4"))
_VARIABLES = ("OPENBLAS_CORETYPE", "NPY_DISABLE_CPU_FEATURES", "NPY_ENABLE_CPU_FEATURES")
_PROBE = "from pushctl.machine import blas_kernels, numpy_simd; print(blas_kernels(), numpy_simd())"


_COMMAND_FIRST = """
import contextlib, io, sys
sys.argv = ["pushctl", "--help"]
from pushctl.cli import main
with contextlib.redirect_stdout(io.StringIO()), contextlib.suppress(SystemExit):
    main()
"""
"""The ``pushctl`` command's start (its help), before the probe."""


def _code_in_a_fresh_process(first: str, **env: str) -> list[str]:
    """(OpenBLAS's kernels, numpy's highest target) in a fresh process that runs ``first``,
    with ``env`` for pushctl's variables."""
    clean = {k: v for k, v in os.environ.items() if k not in _VARIABLES}
    done = subprocess.run(
        [sys.executable, "-c", f"{first}\n{_PROBE}"],
        capture_output=True, text=True, env={**clean, **env}, timeout=300,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    return done.stdout.split()


def test_only_x86_64_with_avx2_and_fma_is_pinned_and_numpy_only_with_avx512() -> None:
    avx2, avx512 = frozenset({"sse2", "avx2", "fma"}), frozenset({"avx2", "fma", "avx512f"})
    assert code_to_pin("x86_64", avx2, "2.4.6") == {"OPENBLAS_CORETYPE": "Haswell"}
    assert code_to_pin("AMD64", avx512, "2.4.0") == {
        "OPENBLAS_CORETYPE": "Haswell", "NPY_DISABLE_CPU_FEATURES": NUMPY_AVX512_TARGETS
    }  # fmt: skip
    assert code_to_pin("x86_64", avx512, "1.26.4")["NPY_DISABLE_CPU_FEATURES"] == (
        OLD_NUMPY_AVX512_TARGETS
    )
    assert code_to_pin("x86_64", frozenset({"sse2", "avx"}), "2.4.6") == {}  # would crash
    assert code_to_pin("aarch64", avx512, "2.4.6") == {}


def test_cpu_flags_reads_the_first_processor_and_nothing_where_there_is_no_file(
    tmp_path: Path,
) -> None:
    info = tmp_path / "cpuinfo"
    info.write_text("processor\t: 0\nflags\t\t: fpu avx2 fma\n\nprocessor\t: 1\nflags\t: fpu\n")
    assert cpu_flags(info) == frozenset({"fpu", "avx2", "fma"})
    assert cpu_flags(tmp_path / "missing") == frozenset()


@pytest.mark.skipif(not _PINNABLE or blas_kernels() == "unknown", reason="no x86-64 AVX2 CPU")
def test_reproducible_first_runs_the_avx2_code_here_and_in_a_fresh_process() -> None:
    # this process: tests/conftest.py calls it before the test modules load numpy
    assert [blas_kernels(), numpy_simd()] == [PINNED_KERNELS, "X86_V3"]
    pinned = "import pushctl; pushctl.reproducible()"
    assert _code_in_a_fresh_process(pinned) == [PINNED_KERNELS, "X86_V3"]
    # the pushctl command makes the call as it starts
    assert _code_in_a_fresh_process(_COMMAND_FIRST) == [PINNED_KERNELS, "X86_V3"]
    # what the user asks for is kept
    chosen = _code_in_a_fresh_process(
        pinned, OPENBLAS_CORETYPE="Sandybridge", NPY_DISABLE_CPU_FEATURES="X86_V3"
    )
    assert chosen[0] == "Sandybridge" and chosen[1] != "X86_V3"
    assert _code_in_a_fresh_process(pinned, NPY_ENABLE_CPU_FEATURES="X86_V3") == [
        PINNED_KERNELS, "X86_V3"
    ]  # fmt: skip


@pytest.mark.skipif(not _PINNABLE, reason="no x86-64 AVX2 CPU: nothing to pin")
def test_numpy_loaded_first_is_left_as_it_is_and_said() -> None:
    code = (
        "import os, warnings, numpy, pushctl; warnings.simplefilter('error'); "
        "from pushctl.machine import NumpyLoadedFirst\n"
        "try:\n    pushctl.reproducible()\nexcept NumpyLoadedFirst as warning:\n"
        "    print('warned' if 'before importing numpy' in str(warning) else warning)\n"
        "print(os.environ.get('OPENBLAS_CORETYPE'))"
    )
    done = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True, text=True, timeout=300,
        env={k: v for k, v in os.environ.items() if k not in _VARIABLES},
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["warned", "None"]


@pytest.mark.skipif(not _PINNABLE or blas_kernels() == "unknown", reason="no x86-64 AVX2 CPU")
def test_ray_workers_run_the_drivers_code(ray_local) -> None:
    import ray

    @ray.remote
    def code() -> list[str]:
        from pushctl.machine import blas_kernels, numpy_simd

        return [blas_kernels(), numpy_simd()]

    assert ray.get(code.remote()) == [PINNED_KERNELS, numpy_simd()]


def test_the_cpu_level_follows_the_flags() -> None:
    v3 = frozenset({"avx2", "fma", "bmi1", "bmi2", "f16c", "movbe", "sse4_2"})
    v4 = v3 | {"avx512f", "avx512bw", "avx512cd", "avx512dq", "avx512vl"}
    assert cpu_level(v4) == "x86-64-v4"
    assert cpu_level(v3 | {"avx512f"}) == "x86-64-v3"
    assert cpu_level(v3 - {"fma"}) == "below x86-64-v3"


def test_scope_differences_name_each_field_that_differs() -> None:
    recorded = {"cpu_vendor": "GenuineIntel", "numpy": "2.4.6", "torch": "2.13.0+cpu"}
    here = {"cpu_vendor": "AuthenticAMD", "numpy": "2.4.6", "torch": "2.13.0+cpu"}
    assert scope_differences(recorded, here) == [
        "cpu_vendor: AuthenticAMD here, GenuineIntel recorded"
    ]
    assert scope_differences(recorded, recorded) == []
