"""What kind of machine a run ran on, for its manifest, and one choice of CPU code for every
x86-64 machine: the last bits of a push depend on it. Its modules hold the rest of what
belongs to the machine: numba's kernel cache (:mod:`.kernel_cache`) and ProxQP's portable
build (:mod:`.proxqp_build`).

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


def cpu_vendor(cpuinfo: Path = Path("/proc/cpuinfo")) -> str:
    """The CPU's vendor as it names itself (``GenuineIntel``, ``AuthenticAMD``), from
    ``cpuinfo`` on Linux; ``unknown`` where it cannot be read."""
    try:
        for line in cpuinfo.read_text().splitlines():
            if line.startswith("vendor_id"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "unknown"


_X86_64_V3 = frozenset({"avx2", "fma", "bmi1", "bmi2", "f16c", "movbe"})
_X86_64_V4 = _X86_64_V3 | {"avx512f", "avx512bw", "avx512cd", "avx512dq", "avx512vl"}


def cpu_level(flags: frozenset[str]) -> str:
    """The x86-64 micro-architecture level that feature ``flags`` reach: ``x86-64-v4``
    (AVX-512), ``x86-64-v3`` (AVX2 and FMA), or ``below x86-64-v3``. Libraries that choose
    their code by CPU (torch's MKL among them) choose by it."""
    if _X86_64_V4 <= flags:
        return "x86-64-v4"
    if _X86_64_V3 <= flags:
        return "x86-64-v3"
    return "below x86-64-v3"


def torch_cpu_capability() -> str:
    """The vector code torch's own kernels run on this CPU (``AVX512``, ``AVX2``,
    ``DEFAULT``; ``ATEN_CPU_CAPABILITY`` lowers it), or ``no torch``. Imports torch."""
    try:
        import torch  # here, not at the top: seconds to load, and it loads numpy
    except ImportError:
        return "no torch"
    return str(torch.backends.cpu.get_cpu_capability())


def _version(distribution: str) -> str:
    try:
        return metadata.version(distribution)
    except metadata.PackageNotFoundError:
        return "not installed"


_LIBRARIES = ("numpy", "scipy", "pin", "proxsuite", "numba", "mujoco", "torch")

SCOPES: dict[str, tuple[str, ...]] = {
    "evaluation": (
        "architecture", "openblas_kernels", "numpy_loops",
        "numpy", "scipy", "pin", "proxsuite", "numba", "mujoco",
    ),
    "training": (
        "architecture", "cpu_vendor", "cpu_level", "openblas_kernels", "numpy_loops",
        "torch_capability", "mkl_cbwr",
        "numpy", "scipy", "pin", "proxsuite", "numba", "mujoco", "torch",
    ),
}  # fmt: skip
"""What must match for a recorded digest to repeat, by kind of run.

- ``evaluation`` (pushes, the policy's forward pass in pushctl's own compiled loop): the
  pinned numpy code and the libraries that step the worlds. Seen equal on the Intel Xeon
  that made the shipped results and on two AMD EPYCs, one with AVX-512 and one without.
- ``training`` adds torch's updates: torch's own kernels choose their vector code by CPU
  (``torch_capability``), and its matrix products run in Intel's MKL, which chooses its code
  by vendor and by level (AVX-512 or not) unless ``MKL_CBWR`` fixes it. (The thread count
  also matters; training sets it, ``[ddpg] torch_threads``.) The same commit and seed
  trained other bits on that Intel Xeon than on the AMD EPYCs; the two EPYCs agreed."""


def reproducibility_scope() -> dict[str, str]:
    """This machine's value of every field of :data:`SCOPES`. Imports numpy and torch."""
    return {
        "architecture": platform.machine(),
        "cpu_vendor": cpu_vendor(),
        "cpu_level": cpu_level(cpu_flags()),
        "openblas_kernels": blas_kernels(),
        "numpy_loops": numpy_simd(),
        "torch_capability": torch_cpu_capability(),
        "mkl_cbwr": os.environ.get("MKL_CBWR", "unset"),
        **{name: _version(name) for name in _LIBRARIES},
    }


def scope_of(kind: str, scope: dict[str, str]) -> dict[str, str]:
    """The fields of ``scope`` that a digest of ``kind`` (a key of :data:`SCOPES`) depends on."""
    return {name: scope[name] for name in SCOPES[kind]}


def scope_differences(recorded: dict[str, str], here: dict[str, str]) -> list[str]:
    """One phrase per field of ``recorded`` whose value ``here`` differs, e.g.
    ``cpu_vendor: AuthenticAMD here, GenuineIntel recorded``."""
    return [
        f"{name}: {here.get(name, 'absent')} here, {value} recorded"
        for name, value in recorded.items()
        if here.get(name) != value
    ]


def machine_description() -> str:
    """One line: the CPU, the cores this process may use, the OpenBLAS kernels numpy runs and
    the highest target its own loops use."""
    return (
        f"{cpu_model()} ({cpu_vendor()}, {cpu_level(cpu_flags())}), {usable_cores()} cores; "
        f"numpy's OpenBLAS runs its {blas_kernels()} "
        f"kernels, its own loops up to {numpy_simd()}"
    )
