"""Build the arm terms' C entry point (``arm_terms.cpp``) against the installed Pinocchio.

Run as ``python -m pushctl.arm.native.build [--optional]`` (the Makefile's ``install`` does,
with ``--optional``). It compiles ``arm_terms.cpp`` with the C++ compiler (``$CXX``, else
``g++``) against the headers and ``libpinocchio_default`` of the ``pin`` wheel in this
environment and Eigen's headers from ``cmeel-eigen``, into
``pushctl/arm/native/lib/libpushctl_arm.so``, with a stamp naming the Pinocchio version and
the source's SHA-256: a later run with both unchanged does nothing, and the loader
(:mod:`pushctl.arm.native`) refuses a library whose stamp does not match. The library is
written to a temporary file and renamed. Without ``--optional`` a failure is an error (exit
1); with it, a one-line note and exit 0: the project then runs the same Pinocchio calls
through its Python bindings, to the same bits, slower.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

from pushctl.arm.native import LIBRARY, SOURCE, STAMP, expected_stamp

DEFINES = (
    # Pinocchio's exported compile definitions (lib/cmake/pinocchio/pinocchioTargets.cmake):
    # the Boost limits its headers were built with, and the explicit template instances.
    "BOOST_MPL_LIMIT_LIST_SIZE=30",
    "BOOST_MPL_LIMIT_VECTOR_SIZE=30",
    "BOOST_MPL_CFG_NO_PREPROCESSED_HEADERS",
    "BOOST_FUSION_INVOKE_MAX_ARITY=12",
    "PINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION",
)


class BuildError(Exception):
    """Why the library could not be built (one line)."""


def cmeel_prefix() -> Path:
    """The ``cmeel.prefix`` directory that holds the installed Pinocchio's headers and
    libraries."""
    import pinocchio

    for parent in Path(pinocchio.__file__).resolve().parents:
        if parent.name == "cmeel.prefix":
            return parent
    raise BuildError(
        f"Pinocchio at {pinocchio.__file__} is not a cmeel wheel (pip install pin): "
        "its headers and libraries were not found"
    )


def compile_command(prefix: Path, output: Path, compiler: str) -> list[str]:
    """The compiler's command line for ``output``."""
    include = prefix / "include"
    return [
        compiler,
        "-O2",
        "-std=c++17",
        "-fPIC",
        "-shared",
        *(f"-D{define}" for define in DEFINES),
        f"-I{include}",
        f"-I{include / 'eigen3'}",
        str(SOURCE),
        "-o",
        str(output),
        f"-L{prefix / 'lib'}",
        "-lpinocchio_default",
        "-lboost_serialization",
        f"-Wl,-rpath,{prefix / 'lib'}",
    ]


def build(force: bool = False) -> str:
    """Build the library unless an up-to-date one exists; returns what was done."""
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
    done = subprocess.run(
        compile_command(prefix, partial, compiler), capture_output=True, text=True
    )
    if done.returncode != 0:
        partial.unlink(missing_ok=True)
        first = next((line for line in done.stderr.splitlines() if "error" in line), "")
        raise BuildError(f"{compiler} failed on {SOURCE.name}: {first.strip()}")
    os.replace(partial, LIBRARY)
    stamp_partial = STAMP.with_name(STAMP.name + f".{os.getpid()}.tmp")
    stamp_partial.write_text(json.dumps(stamp, indent=1) + "\n")
    os.replace(stamp_partial, STAMP)
    return f"built {LIBRARY}"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m pushctl.arm.native.build", description=__doc__.splitlines()[0]
    )
    parser.add_argument(
        "--optional",
        action="store_true",
        help="on failure print a note and exit 0 (the Python bindings' path is used)",
    )
    parser.add_argument("--force", action="store_true", help="rebuild even if up to date")
    args = parser.parse_args(argv)
    try:
        print(build(force=args.force))
    except BuildError as error:
        if args.optional:
            print(
                f"note: the arm terms' library was not built ({error}); "
                "Pinocchio's Python bindings compute the same terms, slower"
            )
            return 0
        print(f"error: {error}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
