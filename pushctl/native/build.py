"""Build pushctl's compiled library (:mod:`pushctl.native`) against the installed Pinocchio
and ProxSuite.

Call :func:`build` (``make install`` does: ``python -c "from pushctl.native.build import
build; print(build(optional=True))"``). It compiles the package's C++ sources with the C++
compiler (``$CXX``, else ``g++``) against the headers and ``libpinocchio_default`` of the
``pin`` wheel in this environment, ProxSuite's headers from the same prefix and Eigen's
from ``cmeel-eigen``, into ``pushctl/native/lib/libpushctl_native.so``, with a stamp naming
the versions and the sources' SHA-256: a later run with all unchanged does nothing, and
the loader refuses a library whose stamp does not match. The library is written to a
temporary file and renamed. A failure raises :class:`BuildError`; with ``optional`` it is
a one-line note instead: the project then runs the same calls through the Python
bindings, to the same bits, slower. About 45 s here (the sources side by side).
"""

from __future__ import annotations

import importlib.util
import json
import os
import shutil
import subprocess
import tempfile
from pathlib import Path

from pushctl.native import LIBRARY, SOURCES, STAMP, expected_stamp

DEFINES = (
    # Pinocchio's exported compile definitions (lib/cmake/pinocchio/pinocchioTargets.cmake):
    # the Boost limits its headers were built with, and the explicit template instances.
    # NDEBUG: a release build, as the wheels' (Eigen's and ProxSuite's checks off).
    "BOOST_MPL_LIMIT_LIST_SIZE=30",
    "BOOST_MPL_LIMIT_VECTOR_SIZE=30",
    "BOOST_MPL_CFG_NO_PREPROCESSED_HEADERS",
    "BOOST_FUSION_INVOKE_MAX_ARITY=12",
    "PINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION",
    "NDEBUG",
)


class BuildError(Exception):
    """Why the library could not be built (one line)."""


def cmeel_prefix() -> Path:
    """The ``cmeel.prefix`` directory that holds the installed Pinocchio's headers and
    libraries."""
    spec = importlib.util.find_spec("pinocchio")  # found, not imported: arm/ imports it
    if spec is None or spec.origin is None:
        raise BuildError("Pinocchio is not installed (pip install pin)")
    for parent in Path(spec.origin).resolve().parents:
        if parent.name == "cmeel.prefix":
            return parent
    raise BuildError(
        f"Pinocchio at {spec.origin} is not a cmeel wheel (pip install pin): "
        "its headers and libraries were not found"
    )


def compile_commands(prefix: Path, objects: Path, output: Path, compiler: str):
    """The compiler's command lines: one per source (run side by side), then the link."""
    include = prefix / "include"
    # No -march: the baseline x86-64 instruction set (SSE2), as ProxSuite's portable
    # bindings, whose answers pushctl's must equal to the bit (pushctl/machine/proxqp_build.py).
    flags = ["-O2", "-std=c++17", "-fPIC", *(f"-D{define}" for define in DEFINES)]
    flags += [f"-I{include}", f"-I{include / 'eigen3'}"]
    compiles = [
        [compiler, *flags, "-c", str(source), "-o", str(objects / f"{source.stem}.o")]
        for source in SOURCES
    ]
    link = [
        compiler, "-shared", *(command[-1] for command in compiles), "-o", str(output),
        f"-L{prefix / 'lib'}", "-lpinocchio_default", "-lboost_serialization",
        f"-Wl,-rpath,{prefix / 'lib'}",
    ]  # fmt: skip
    return compiles, link


def _run_all(commands: list[list[str]]) -> None:
    """Run the commands side by side; BuildError with the first error line of a failure."""
    running = [
        subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        for command in commands
    ]
    for command, process in zip(commands, running, strict=True):
        _, stderr = process.communicate()
        if process.returncode != 0:
            first = next((line for line in stderr.splitlines() if "error" in line), stderr)
            raise BuildError(f"{command[0]} failed: {first.strip()[:300]}")


def build(force: bool = False, optional: bool = False) -> str:
    """Build the library unless an up-to-date one exists (``force``: rebuild); returns what
    was done. A failure raises :class:`BuildError`, or with ``optional`` is returned as a
    note (the Python bindings are then used)."""
    try:
        return _build(force)
    except BuildError as error:
        if not optional:
            raise
        return (
            f"note: pushctl's compiled library was not built ({error}); "
            "the Python bindings compute the same numbers, slower"
        )


def _build(force: bool) -> str:
    """:func:`build` without the note."""
    stamp = expected_stamp()
    if not force and LIBRARY.exists() and STAMP.exists():
        if json.loads(STAMP.read_text()) == stamp:
            return f"{LIBRARY} is up to date"
    prefix = cmeel_prefix()
    if not (prefix / "include" / "eigen3" / "Eigen").is_dir():
        raise BuildError("Eigen's headers were not found: pip install cmeel-eigen")
    compiler = os.environ.get("CXX", "g++")
    if shutil.which(compiler) is None:
        raise BuildError(f"no C++ compiler {compiler!r} on the PATH (set CXX to name one)")
    LIBRARY.parent.mkdir(parents=True, exist_ok=True)
    partial = LIBRARY.with_name(LIBRARY.name + f".{os.getpid()}.tmp")
    with tempfile.TemporaryDirectory() as objects:
        compiles, link = compile_commands(prefix, Path(objects), partial, compiler)
        try:
            _run_all(compiles)
            _run_all([link])
        except BuildError:
            partial.unlink(missing_ok=True)
            raise
    os.replace(partial, LIBRARY)
    stamp_partial = STAMP.with_name(STAMP.name + f".{os.getpid()}.tmp")
    stamp_partial.write_text(json.dumps(stamp, indent=1) + "\n")
    os.replace(stamp_partial, STAMP)
    return f"built {LIBRARY}"
