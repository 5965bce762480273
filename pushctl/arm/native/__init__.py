"""The arm's terms from compiled code: Pinocchio's algorithms behind a C entry point
(``arm_terms.cpp``), called from a numba kernel instead of through the Python bindings.

:meth:`pushctl.arm.ArmModel.compute` makes one Python call to computeAllTerms and one per
frame (the prongs, the pusher, the nominal pusher): about a dozen microseconds, a third of a
world step. Through this module the same pass is one compiled call (:func:`native_terms`)
that runs the same Pinocchio instances (those of ``libpinocchio_default``), so the same
bits (tests/arm/test_native.py).

The library is built at install (``python -m pushctl.arm.native.build``). :func:`available`
says whether it is loaded: it is used only if it was built for the installed Pinocchio from
today's source (its stamp) and ``PUSHCTL_NATIVE`` is not ``0``; otherwise
:class:`~pushctl.arm.ArmModel` keeps to the bindings, with the same results.
"""

from __future__ import annotations

import ctypes
import hashlib
import json
import os
from pathlib import Path

import pinocchio as pin

SOURCE = Path(__file__).with_name("arm_terms.cpp")
"""The C++ source of the entry point."""
LIBRARY = Path(__file__).parent / "lib" / "libpushctl_arm.so"
"""Where the build puts the library (not in git)."""
STAMP = LIBRARY.with_suffix(".json")
"""What the library was built from (:func:`expected_stamp`)."""

_loaded: ctypes.CDLL | None = None
_checked = False


def expected_stamp() -> dict[str, str]:
    """The stamp a usable library carries: the installed Pinocchio's version and the
    source's SHA-256."""
    return {
        "pinocchio": pin.__version__,
        "source_sha256": hashlib.sha256(SOURCE.read_bytes()).hexdigest(),
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

    # numba's kernels name the entry point by its symbol: the library must be loaded
    # into the process's global symbols before any of them is compiled or loaded.
    llvmlite.binding.load_library_permanently(str(LIBRARY))
    library = ctypes.CDLL(str(LIBRARY))
    library.pushctl_arm_create.restype = ctypes.c_void_p
    library.pushctl_arm_create.argtypes = [ctypes.c_char_p, ctypes.c_int64]
    library.pushctl_arm_free.restype = None
    library.pushctl_arm_free.argtypes = [ctypes.c_void_p]
    _loaded = library
    return library


def available() -> bool:
    """Whether the compiled arm terms are in use in this process."""
    return _load() is not None


def status() -> str:
    """One line saying which path computes the arm terms in this process, and why."""
    if available():
        return f"compiled ({LIBRARY.name}, Pinocchio {pin.__version__})"
    if os.environ.get("PUSHCTL_NATIVE", "1") == "0":
        return "Pinocchio's Python bindings (PUSHCTL_NATIVE=0)"
    if not LIBRARY.exists():
        return "Pinocchio's Python bindings (not built: python -m pushctl.arm.native.build)"
    return "Pinocchio's Python bindings (built for another Pinocchio or source: rebuild it)"


class NativeArm:
    """A copy of one Pinocchio model (and a Data of its own) inside the library.

    ``handle``: its address, the first argument of :func:`native_terms`. Made from the
    model's text serialisation, so it must be made again if the model changes
    (:meth:`pushctl.arm.ArmModel.set_gravity` does); freed with this object."""

    def __init__(self, model: pin.Model) -> None:
        library = _load()
        if library is None:
            raise RuntimeError("the arm terms' library is not loaded (available() is False)")
        text = model.saveToString().encode()
        handle = library.pushctl_arm_create(text, len(text))
        if not handle:
            raise RuntimeError("the arm terms' library could not load the model")
        self.handle: int = handle
        self._free = library.pushctl_arm_free

    def __del__(self) -> None:
        handle, self.handle = getattr(self, "handle", 0), 0
        if handle:
            self._free(handle)
