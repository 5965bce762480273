"""ProxSuite's ProxQP, loaded from its portable (SSE2) build, so that a QP's answer does not
depend on where its memory lies.

ProxSuite ships its bindings built three times and loads the widest the CPU runs: AVX-512,
else AVX2, else a portable SSE2 build. The two vectorised builds answer with last bits that
depend on where a QP's workspace lands in memory. One cold-path MLCP recorded from a push
(12 rows), solved by 60 QP objects made one after another in one process with allocations
between, gave two different answers with the AVX-512 build and two with AVX2, one with the
portable build. Within a process one reused
QP per size hides it; across processes the addresses differ (address-space randomisation),
so a push that reached ProxQP could end in a different one of two valid contact solutions
in two runs of one command. The portable build is the same library on every x86-64 machine.

ProxSuite has no switch for its choice: its ``__init__`` asks its ``instructionset``
module. While proxsuite is first imported here, that module is a stand-in that reports
neither AVX2 nor AVX-512 (it is removed again at once). Import ProxQP from this module
(``from pushctl.machine.proxqp_build import proxqp``), never from ``proxsuite`` directly, and import
this module before anything that imports proxsuite (qpsolvers does: pushctl.objects.mass
imports this module first).
"""

from __future__ import annotations

import importlib
import sys
import types

PORTABLE_MODULE = "proxsuite.proxsuite_pywrap"
"""The bindings' portable build (the vectorised ones end in ``_avx2``, ``_avx512``)."""


def _import_portable() -> types.ModuleType:
    """proxsuite with its portable bindings; ImportError if it was imported before with
    another build (one process can hold only one of them)."""
    if "proxsuite" not in sys.modules:
        stand_in = types.ModuleType("proxsuite.instructionset")
        stand_in.has_AVX512F = lambda: False  # type: ignore[attr-defined]
        stand_in.has_AVX2 = lambda: False  # type: ignore[attr-defined]
        sys.modules[stand_in.__name__] = stand_in
        try:
            importlib.import_module("proxsuite")
        finally:
            del sys.modules[stand_in.__name__]
    proxsuite = sys.modules["proxsuite"]
    loaded = getattr(proxsuite, "_submodule", None)
    name = getattr(loaded, "__name__", "?")
    if name != PORTABLE_MODULE:
        raise ImportError(
            f"proxsuite was imported with its {name} bindings before pushctl's; import "
            "pushctl.machine.proxqp_build before proxsuite or qpsolvers (it loads "
            f"{PORTABLE_MODULE}, whose answers do not depend on memory layout)"
        )
    return proxsuite


proxsuite = _import_portable()
proxqp = proxsuite.proxqp
