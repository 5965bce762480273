"""Which OpenBLAS kernels numpy runs on this machine: the recorded digests of a push are
per kernel family, because OpenBLAS picks its kernels by CPU at load time and their sums
round differently (a `wedge constant` push on an AMD EPYC, OpenBLAS's `Haswell` kernels,
against the same push where the digests were first recorded, a machine with AVX-512;
`OPENBLAS_CORETYPE=Sandybridge` or `Prescott` on the AMD machine gives two more digests).
Within one machine every run repeats to the bit (tests/contact/test_bit_exact.py)."""

from __future__ import annotations

import ctypes
from pathlib import Path

import numpy as np


def openblas_kernels() -> str:
    """OpenBLAS's name for the kernels numpy's copy of it chose (e.g. ``Haswell``,
    ``SkylakeX``), or ``unknown`` where numpy brings no OpenBLAS of that build."""
    libs = sorted((Path(np.__file__).parent.parent / "numpy.libs").glob("*openblas*"))
    for lib in libs:
        library = ctypes.CDLL(str(lib))
        for symbol in ("scipy_openblas_get_corename64_", "openblas_get_corename64_"):
            corename = getattr(library, symbol, None)
            if corename is not None:
                corename.restype = ctypes.c_char_p
                return corename().decode()
    return "unknown"
