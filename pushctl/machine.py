"""What kind of machine a run ran on, for its manifest: the last bits of a push depend on it.

numpy's OpenBLAS picks its kernels by CPU when it loads, and their sums round differently:
the same commit and seed push to other last bits on a machine whose OpenBLAS runs its
``Haswell`` kernels than on one with AVX-512 (docs/reproducibility.md). A run repeats to the
byte on a machine of the same kind, which this names.
"""

from __future__ import annotations

import ctypes
import os
import platform
from pathlib import Path

import numpy as np

_CORENAME_SYMBOLS = ("scipy_openblas_get_corename64_", "openblas_get_corename64_")


def blas_kernels() -> str:
    """OpenBLAS's name for the kernels numpy's copy of it runs (e.g. ``Haswell``,
    ``SkylakeX``), or ``unknown`` where numpy brings no OpenBLAS that says."""
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
