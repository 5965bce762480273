"""Which OpenBLAS kernels numpy runs on this machine (:func:`pushctl.machine.blas_kernels`):
the recorded digests of a push are per kernel family, because OpenBLAS picks its kernels by
CPU at load time and their sums round differently (a `wedge constant` push on an AMD EPYC,
OpenBLAS's `Haswell` kernels, against the same push where the digests were first recorded,
a machine with AVX-512; `OPENBLAS_CORETYPE=Sandybridge` or `Prescott` on the AMD machine
gives two more digests). Within one machine every run repeats to the bit
(tests/contact/test_bit_exact.py)."""

from __future__ import annotations

from pushctl.machine import blas_kernels


def openblas_kernels() -> str:
    """OpenBLAS's name for the kernels numpy's copy of it chose, or ``unknown``."""
    return blas_kernels()
