"""pushctl's compiled library: Pinocchio's and ProxSuite's own algorithms behind C entry
points, so that the hot loops reach them without a Python call each.

- ``arm_terms.cpp``: the arm's pass of every world step (:meth:`pushctl.arm.ArmModel.compute`:
  computeAllTerms and the frames' Jacobians; and ``integrate``), called from numba kernels
  (:mod:`pushctl.native.arm_kernels`, ``pushctl.contact.compiled.step_end``). Through the
  bindings it was one Python call to computeAllTerms and one per frame: about a third of a
  world step.
- ``force_qps.cpp``: the force distribution's sequence of small ProxQP problems, one per
  planned step (:class:`pushctl.planning.forces._StepQP`), about 7500 per reset, each a
  Python round trip through the bindings.

Both run the very code the Python bindings run (Pinocchio's instances exported by the
installed ``libpinocchio_default``; ProxSuite's header-only solver built, like the portable
bindings pushctl loads, for the baseline x86-64 instruction set), so every number is the
bindings' to the bit (tests/native/).

The library is built at install (``pushctl.native.build.build()``; the Makefile does it).
:func:`available` says whether it is in use: only if it was built for the installed
Pinocchio and ProxSuite from today's sources (its stamp) and ``PUSHCTL_NATIVE`` is not
``0``. Otherwise the callers keep to the bindings, with the same results, slower.
"""

from __future__ import annotations

import ctypes
import hashlib
import json
import os
from importlib import metadata
from pathlib import Path

SOURCES = (
    Path(__file__).with_name("arm_terms.cpp"),
    Path(__file__).with_name("force_qps.cpp"),
)
"""The C++ sources of the library."""
LIBRARY = Path(__file__).parent / "lib" / "libpushctl_native.so"
"""Where the build puts the library (not in git)."""
STAMP = LIBRARY.with_suffix(".json")
"""What the library was built from (:func:`expected_stamp`)."""

_loaded: ctypes.CDLL | None = None
_checked = False
_load_error: str | None = None


def expected_stamp() -> dict[str, str]:
    """The stamp a usable library carries: the installed Pinocchio's and ProxSuite's
    versions and the sources' SHA-256."""
    digest = hashlib.sha256()
    for source in SOURCES:
        digest.update(source.read_bytes())
    return {
        "pinocchio": metadata.version("pin"),
        "proxsuite": metadata.version("proxsuite"),
        "sources_sha256": digest.hexdigest(),
    }


def _load() -> ctypes.CDLL | None:
    global _loaded, _checked
    if _checked:
        return _loaded
    _checked = True
    if os.environ.get("PUSHCTL_NATIVE", "1") == "0" or not LIBRARY.exists():
        return None
    try:
        if json.loads(STAMP.read_text()) != expected_stamp():
            return None
    except (OSError, ValueError):
        return None
    import llvmlite.binding

    global _load_error
    try:
        # numba's kernels name the entry points by their symbols: the library must be
        # loaded into the process's global symbols before any of them is compiled or loaded.
        llvmlite.binding.load_library_permanently(str(LIBRARY))
        library = ctypes.CDLL(str(LIBRARY))
    except (OSError, RuntimeError) as error:  # e.g. the Pinocchio it was linked to is gone
        _load_error = str(error).splitlines()[0] if str(error) else type(error).__name__
        return None
    pointer, size = ctypes.c_void_p, ctypes.c_int64
    library.pushctl_arm_create.restype = pointer
    library.pushctl_arm_create.argtypes = [ctypes.c_char_p, size]
    library.pushctl_arm_free.restype = None
    library.pushctl_arm_free.argtypes = [pointer]
    library.pushctl_force_qps.restype = None
    library.pushctl_force_qps.argtypes = [
        size, size, pointer, pointer, pointer, pointer, size, pointer, ctypes.c_double,
        size, pointer, pointer,
    ]  # fmt: skip
    _loaded = library
    return library


def available() -> bool:
    """Whether the compiled library is in use in this process."""
    return _load() is not None


def library() -> ctypes.CDLL:
    """The loaded library; RuntimeError where it is not in use (see :func:`available`)."""
    loaded = _load()
    if loaded is None:
        raise RuntimeError("pushctl's compiled library is not in use (available() is False)")
    return loaded


def status() -> str:
    """One line saying whether the compiled library is in use in this process, and why."""
    if available():
        return f"compiled ({LIBRARY.name}, Pinocchio {metadata.version('pin')})"
    if os.environ.get("PUSHCTL_NATIVE", "1") == "0":
        return "Pinocchio's and ProxSuite's Python bindings (PUSHCTL_NATIVE=0)"
    if not LIBRARY.exists():
        return "the Python bindings (not built: pushctl.native.build.build())"
    if _load_error is not None:
        return f"the Python bindings (the library did not load: {_load_error}; rebuild it)"
    return "the Python bindings (built for other versions or sources: rebuild it)"


class NativeArm:
    """A copy of one Pinocchio model (and a Data of its own) inside the library.

    Made from the model's text serialisation (``pin.Model.saveToString()``: this package
    does not import Pinocchio, :mod:`pushctl.arm` does), so it must be made again if the
    model changes (:meth:`pushctl.arm.ArmModel.set_gravity` does). ``handle``: its
    address, the first argument of the arm kernels. Freed with this object."""

    def __init__(self, serialised_model: str) -> None:
        loaded = library()
        text = serialised_model.encode()
        handle = loaded.pushctl_arm_create(text, len(text))
        if not handle:
            raise RuntimeError("pushctl's compiled library could not load the model")
        self.handle: int = handle
        self._free = loaded.pushctl_arm_free

    def __del__(self) -> None:
        handle, self.handle = getattr(self, "handle", 0), 0
        if handle:
            self._free(handle)
