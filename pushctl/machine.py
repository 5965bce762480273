"""What kind of machine a run ran on, for its manifest, and one OpenBLAS kernel family for
every x86-64 machine: the last bits of a push depend on the kernels.

numpy's OpenBLAS picks its kernels by CPU when it loads, and their sums round differently:
with AVX-512 it runs its ``SkylakeX`` kernels, without it its ``Haswell`` ones, and the same
commit and seed push to other last bits; on an AVX-512 machine two fresh processes even
wrote different bytes (docs/reproducibility.md). Every x86-64 CPU with AVX2 and FMA runs the
``Haswell`` kernels, so :func:`pin_blas_kernels` asks OpenBLAS for them through
``OPENBLAS_CORETYPE``, which OpenBLAS reads once, when numpy loads it: ``pushctl/__init__.py``
calls it before anything imports numpy (Ray's workers inherit the variable). A value the
user set is kept, and a CPU without AVX2 and FMA is left to OpenBLAS's choice (OpenBLAS
does not check a forced family: those kernels would crash there). The manifest names the
kernels that ran (:func:`machine_description`).

numpy is imported inside the functions that need it: importing it here would load OpenBLAS
before the variable is set.
"""

from __future__ import annotations

import ctypes
import os
import platform
import sys
from pathlib import Path

PINNED_KERNELS = "Haswell"
"""The OpenBLAS kernel family pushctl runs on x86-64 (the one the shipped ``results/`` and
the tests' recorded digests were made with)."""


def cpu_flags(cpuinfo: Path = Path("/proc/cpuinfo")) -> frozenset[str]:
    """The first CPU's feature flags from ``cpuinfo`` (Linux); empty where it cannot be read."""
    try:
        for line in cpuinfo.read_text().splitlines():
            if line.startswith("flags"):
                return frozenset(line.split(":", 1)[1].split())
    except OSError:
        pass
    return frozenset()


def kernels_to_pin(machine: str, flags: frozenset[str]) -> str | None:
    """The kernel family to force on a CPU of architecture ``machine`` (``platform.machine()``)
    with feature ``flags``, or None where none can be forced safely."""
    if machine.lower() in ("x86_64", "amd64") and {"avx2", "fma"} <= flags:
        return PINNED_KERNELS
    return None


def pin_blas_kernels() -> str | None:
    """Set ``OPENBLAS_CORETYPE`` for this process and its children before numpy loads.
    Returns the family asked for from now on (None: OpenBLAS chooses by CPU); once numpy is
    loaded nothing can change, and the variable as it stands is returned."""
    if "numpy" in sys.modules:
        return os.environ.get("OPENBLAS_CORETYPE")
    chosen = os.environ.get("OPENBLAS_CORETYPE") or kernels_to_pin(platform.machine(), cpu_flags())
    if chosen:
        os.environ["OPENBLAS_CORETYPE"] = chosen
    return chosen


_CORENAME_SYMBOLS = ("scipy_openblas_get_corename64_", "openblas_get_corename64_")


def blas_kernels() -> str:
    """OpenBLAS's name for the kernels numpy's copy of it runs (e.g. ``Haswell``,
    ``SkylakeX``), or ``unknown`` where numpy brings no OpenBLAS that says."""
    import numpy as np  # here, not at the top: see the module docstring

    for lib in sorted((Path(np.__file__).parent.parent / "numpy.libs").glob("*openblas*")):
        try:
            library = ctypes.CDLL(str(lib))
        except OSError:
            continue
        for symbol in _CORENAME_SYMBOLS:
            corename = getattr(library, symbol, None)
            if corename is not None:
                corename.restype = ctypes.c_char_p
                return corename().decode()
    return "unknown"


def cpu_model() -> str:
    """The CPU's model name (``/proc/cpuinfo`` on Linux), else what ``platform`` says."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine() or "unknown"


def machine_description() -> str:
    """One line: the CPU, the cores this process may use, and the OpenBLAS kernels numpy
    runs."""
    if hasattr(os, "sched_getaffinity"):
        cores = len(os.sched_getaffinity(0))
    else:
        cores = os.cpu_count() or 1
    return f"{cpu_model()}, {cores} cores; numpy's OpenBLAS runs its {blas_kernels()} kernels"
