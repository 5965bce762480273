"""numba's disk cache of pushctl's kernels kept in step with every file they are compiled from.

numba keys a cached kernel by its own source file (modification time and size) and the
kernel's bytecode, not by the files of the kernels it calls: ``contact/cold_step.py``
compiles ``contact/kernels.py``'s and ``contact/pivot_kernels.py``'s kernels into its own,
``contact/step_end.py`` the library symbols declared in ``native/arm_kernels.py``. After an
edit of a callee's file the caller's cached code still runs the old callee: wrong results,
or, where a return type changed, numba failing to box a result ("'descr' is NULL").

:func:`drop_stale` runs before any kernel is loaded (``import pushctl``). For each pushctl
file that defines kernels it hashes the pushctl files that file imports from, directly or
through the files it imports (numba compiles a callee's callees in too); where the
hash differs from the one recorded beside the file's cache (``__pycache__/<name>.deps``),
it removes that file's cached kernels, which numba then compiles afresh, and records the
new hash. A clean clone records every hash on its first import and removes nothing; two
processes meeting the same stale cache at worst both compile.
"""

from __future__ import annotations

import hashlib
import os
import re
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent
_KERNEL = re.compile(r"^@njit", re.MULTILINE)
"""What marks a file as one that defines compiled kernels: a line opening with ``@njit``."""
_IMPORT = re.compile(r"^from (pushctl(?:\.\w+)+) import", re.MULTILINE)


def kernel_files(package: Path = PACKAGE) -> dict[Path, tuple[Path, ...]]:
    """Each file of ``package`` that defines kernels → the package's files it imports from,
    directly or through them (its dependencies: whatever of theirs it compiles in, and what
    those compile in: ``contact/cold_step.py`` compiles ``contact/kernels.py``'s kernels,
    and with them ``contact/small_algebra.py``'s)."""
    imports: dict[Path, tuple[Path, ...]] = {}
    kernels = []
    for path in sorted(package.rglob("*.py")):
        source = path.read_text(encoding="utf-8")
        modules = sorted(set(_IMPORT.findall(source)))
        imports[path] = tuple(p for p in (_module_file(package, m) for m in modules) if p)
        if _KERNEL.search(source):
            kernels.append(path)
    return {path: _reachable(path, imports) for path in kernels}


def _reachable(start: Path, imports: dict[Path, tuple[Path, ...]]) -> tuple[Path, ...]:
    """The files ``start`` imports from, directly or not, sorted (``start`` left out)."""
    seen: set[Path] = set()
    todo = list(imports.get(start, ()))
    while todo:
        path = todo.pop()
        if path not in seen and path != start:
            seen.add(path)
            todo.extend(imports.get(path, ()))
    return tuple(sorted(seen))


def drop_stale(package: Path = PACKAGE) -> list[Path]:
    """Remove the cached kernels of every file whose dependencies changed since its cache
    was recorded (see the module docstring). Returns the files whose caches were removed.
    Never raises for a cache it cannot write (a read-only install): numba then checks what
    it can itself. With ``NUMBA_CACHE_DIR`` set the caches live elsewhere and are left
    alone."""
    dropped: list[Path] = []
    if os.environ.get("NUMBA_CACHE_DIR"):
        return dropped
    for path, dependencies in kernel_files(package).items():
        digest = hashlib.sha256()
        for dependency in dependencies:
            digest.update(dependency.relative_to(package).as_posix().encode())
            digest.update(dependency.read_bytes())
        stamp = path.parent / "__pycache__" / f"{path.stem}.deps"
        try:
            if stamp.exists() and stamp.read_text() == digest.hexdigest():
                continue
            cached = sorted(stamp.parent.glob(f"{path.stem}.*.nb[ic]"))
            for entry in cached:
                entry.unlink(missing_ok=True)
            if cached:
                dropped.append(path)
            stamp.parent.mkdir(exist_ok=True)
            partial = stamp.with_name(f"{stamp.name}.{os.getpid()}.tmp")
            partial.write_text(digest.hexdigest())
            partial.replace(stamp)
        except OSError:
            continue
    return dropped


def _module_file(package: Path, module: str) -> Path | None:
    """The file of pushctl module ``module`` (a package's ``__init__.py``), or None."""
    parts = module.split(".")[1:]
    base = package.joinpath(*parts)
    for candidate in (base.with_suffix(".py"), base / "__init__.py"):
        if candidate.is_file():
            return candidate
    return None
