"""What kind of machine a run ran on, for its manifest, and one choice of CPU code for every
x86-64 machine: the last bits of a push depend on it.

numpy picks code by CPU when it loads, and the choices round differently. Its OpenBLAS runs
its ``SkylakeX`` kernels with AVX-512 and its ``Haswell`` ones without, and its own loops
(``np.sin``, sums, …) have AVX-512 versions too. With either, the same commit and seed
pushed to other last bits than on a machine without AVX-512; with OpenBLAS's AVX-512
kernels, two fresh processes on one machine even wrote different bytes, and with numpy's
AVX-512 loops a ``paper`` training run left the shipped one (docs/reproducibility.md).
Every x86-64 CPU with AVX2 and FMA runs the AVX2 code, so :func:`reproducible` asks for it:
``OPENBLAS_CORETYPE=Haswell``, and on a CPU with AVX-512, ``NPY_DISABLE_CPU_FEATURES``
naming numpy's AVX-512 targets. Both are read once, when numpy loads, so the call must come
before anything imports numpy (``import pushctl`` does not; the ``pushctl`` command makes
the call first; Ray's workers inherit the variables). A value the user set is kept, and a
CPU without AVX2 and FMA is left to the libraries' choice (OpenBLAS does not check a forced
family: those kernels would crash there). The manifest names the code that ran
(:func:`machine_description`).

numpy is imported inside the functions that need it: importing it here would load it
before the variables are set.
"""

from __future__ import annotations

import ctypes
import importlib
import os
import platform
import sys
import warnings
from importlib import metadata
from pathlib import Path

PINNED_KERNELS = "Haswell"
"""The OpenBLAS kernel family pushctl runs on x86-64 (the one the shipped ``results/`` and
the tests' recorded digests were made with)."""

NUMPY_AVX512_TARGETS = "X86_V4 AVX512_ICL AVX512_SPR"
"""numpy's AVX-512 dispatch targets from numpy 2.4 on (checked on 2.4: with these disabled
its highest target is ``X86_V3``, AVX2)."""

OLD_NUMPY_AVX512_TARGETS = (
    "AVX512F AVX512CD AVX512_KNL AVX512_KNM AVX512_SKX AVX512_CLX AVX512_CNL AVX512_ICL AVX512_SPR"
)
"""The same before numpy 2.4, which named them by feature (names a build did not dispatch
only raise an ImportWarning, ignored by default)."""


def cpu_flags(cpuinfo: Path = Path("/proc/cpuinfo")) -> frozenset[str]:
    """The first CPU's feature flags from ``cpuinfo`` (Linux); empty where it cannot be read."""
    try:
        for line in cpuinfo.read_text().splitlines():
            if line.startswith("flags"):
                return frozenset(line.split(":", 1)[1].split())
    except OSError:
        pass
    return frozenset()


def code_to_pin(machine: str, flags: frozenset[str], numpy_version: str) -> dict[str, str]:
    """The environment variables that make a CPU of architecture ``machine``
    (``platform.machine()``) with feature ``flags`` run the AVX2 code of OpenBLAS and of
    numpy ``numpy_version``; empty where that cannot be forced safely."""
    if machine.lower() not in ("x86_64", "amd64") or not {"avx2", "fma"} <= flags:
        return {}
    pinned = {"OPENBLAS_CORETYPE": PINNED_KERNELS}
    if "avx512f" in flags:
        major_minor = tuple(int(part) for part in numpy_version.split(".")[:2])
        old = major_minor < (2, 4)
        pinned["NPY_DISABLE_CPU_FEATURES"] = (
            OLD_NUMPY_AVX512_TARGETS if old else NUMPY_AVX512_TARGETS
        )
    return pinned


class NumpyLoadedFirst(RuntimeWarning):
    """:func:`reproducible` came after numpy loaded: this process runs the code numpy chose."""


def reproducible() -> dict[str, str]:
    """Pin numpy's and OpenBLAS's CPU code (:func:`code_to_pin`) for this process and its
    children, so that a seed gives the same bytes on every x86-64 machine. Call it before
    anything imports numpy::

        import pushctl
        pushctl.reproducible()

    Variables the user set are kept (numpy refuses both ``NPY_DISABLE_CPU_FEATURES`` and
    ``NPY_ENABLE_CPU_FEATURES``, so a user's ``NPY_ENABLE_CPU_FEATURES`` keeps numpy's part
    unset). Returns the variables it set. Once numpy is loaded it is too late: it sets
    nothing and warns (:class:`NumpyLoadedFirst`) if this machine needed any."""
    try:
        numpy_version = metadata.version("numpy")
    except metadata.PackageNotFoundError:
        numpy_version = "0"
    wanted = code_to_pin(platform.machine(), cpu_flags(), numpy_version)
    if "NPY_ENABLE_CPU_FEATURES" in os.environ:
        wanted.pop("NPY_DISABLE_CPU_FEATURES", None)
    chosen = {name: value for name, value in wanted.items() if name not in os.environ}
    if chosen and "numpy" in sys.modules:
        settings = " ".join(f"{name}={value!r}" for name, value in chosen.items())
        warnings.warn(
            "numpy was loaded before pushctl.reproducible(): this process keeps the CPU code "
            f"numpy chose; call it before importing numpy, or start Python with {settings}",
            NumpyLoadedFirst,
            stacklevel=2,
        )
        return {}
    os.environ.update(chosen)
    return chosen


def numpy_simd() -> str:
    """The highest of numpy's dispatch targets that its loops use on this CPU (e.g.
    ``X86_V3``, ``X86_V4``), or ``baseline``."""
    try:  # here, not at the top: see the module docstring
        umath = importlib.import_module("numpy._core._multiarray_umath")  # numpy >= 2
    except ImportError:  # pragma: no cover - numpy 1.x
        umath = importlib.import_module("numpy.core._multiarray_umath")
    features = umath.__cpu_features__
    used = [target for target in umath.__cpu_dispatch__ if features.get(target)]
    return used[-1] if used else "baseline"


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


def usable_cores() -> int:
    """The cores this process may run on (its affinity on Linux, else all of them)."""
    if hasattr(os, "sched_getaffinity"):
        return len(os.sched_getaffinity(0))
    return os.cpu_count() or 1


def machine_description() -> str:
    """One line: the CPU, the cores this process may use, the OpenBLAS kernels numpy runs and
    the highest target its own loops use."""
    return (
        f"{cpu_model()}, {usable_cores()} cores; numpy's OpenBLAS runs its {blas_kernels()} "
        f"kernels, its own loops up to {numpy_simd()}"
    )
