"""numba's disk cache of pushctl's kernels kept in step with every file they are compiled from.

numba keys a cached kernel by its own source file (modification time and size) and the
kernel's bytecode, not by the files of the kernels it calls: ``contact/compiled/step.py``
compiles ``contact/compiled/assembly.py``'s and ``contact/compiled/pivoting.py``'s kernels
into its own, ``contact/compiled/step_end.py`` the library symbols declared in
``native/arm_kernels.py``. After an
edit of a callee's file the caller's cached code still runs the old callee: wrong results,
or, where a return type changed, numba failing to box a result ("'descr' is NULL").

:func:`drop_stale` is called explicitly, before any kernel is loaded: by the ``pushctl``
command and by the test suite (``import pushctl`` deletes nothing). For each pushctl file
that defines kernels it hashes the pushctl files that file imports from, directly or
through the files it imports (numba compiles a callee's callees in too; the imports are
read with :mod:`ast`, every form of them); where the hash differs from the one recorded
beside the file's cache (``__pycache__/<name>.deps``), it removes that file's cached
kernels, which numba then compiles afresh, and records the new hash. It touches nothing
outside the package's own ``__pycache__`` directories. A clean clone records every hash on
its first call and removes nothing; two processes meeting the same stale cache at worst
both compile.
"""

from __future__ import annotations

import ast
import hashlib
import os
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1]


def kernel_files(package: Path = PACKAGE) -> dict[Path, tuple[Path, ...]]:
    """Each file of ``package`` that defines kernels (a function decorated with numba's
    ``njit``) → the package's files it imports from, directly or through them (its
    dependencies: whatever of theirs it compiles in, and what those compile in)."""
    imports: dict[Path, tuple[Path, ...]] = {}
    kernels = []
    for path in sorted(package.rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
        modules = _imported_modules(tree, _module_name(package, path))
        found = (_module_file(package, module) for module in sorted(modules))
        imports[path] = tuple(sorted({file for file in found if file is not None}))
        if _defines_kernels(tree):
            kernels.append(path)
    return {path: _reachable(path, imports) for path in kernels}


def _imported_modules(tree: ast.Module, name: str) -> set[str]:
    """The modules of the package that ``tree`` (module ``name``) imports, in any form:
    ``import a.b``, ``from a import b`` (``a.b`` if a module, else ``a``), relative ones."""
    root = name.split(".")[0]
    found: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names if alias.name.split(".")[0] == root}
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = name.rsplit(".", node.level)[0]
                base = f"{anchor}.{base}" if base else anchor
            if base.split(".")[0] == root:
                found.add(base)
                found |= {f"{base}.{alias.name}" for alias in node.names}
    return found


def _defines_kernels(tree: ast.Module) -> bool:
    """Whether a function in ``tree`` is decorated with ``njit`` (``@njit``, ``@njit(...)``,
    ``@numba.njit``...)."""
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef):
            for decorator in node.decorator_list:
                target = decorator.func if isinstance(decorator, ast.Call) else decorator
                label = target.attr if isinstance(target, ast.Attribute) else target
                if getattr(label, "id", label) == "njit":
                    return True
    return False


def _module_name(package: Path, path: Path) -> str:
    """The dotted name of ``path`` in ``package`` (a package's ``__init__`` is the package)."""
    parts = [package.name, *path.relative_to(package).with_suffix("").parts]
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


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
    """The file of module ``module`` of ``package`` (a package's ``__init__.py``), or None
    (a name imported from a module, not a module)."""
    parts = module.split(".")[1:]
    base = package.joinpath(*parts)
    for candidate in (base.with_suffix(".py"), base / "__init__.py"):
        if candidate.is_file():
            return candidate
    return None
