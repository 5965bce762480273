"""numba's cached kernels are dropped when a file they compile in changes, and only then."""

from __future__ import annotations

from pathlib import Path

from pushctl.machine.kernel_cache import PACKAGE, drop_stale, kernel_files


def _package(root: Path) -> Path:
    """A package with a kernel file that imports from another (numba's cache layout)."""
    package = root / "pushctl"
    (package / "__pycache__").mkdir(parents=True)
    (package / "callee.py").write_text("def f():\n    return 1\n")
    (package / "caller.py").write_text(
        "from pushctl.callee import f\n\n@njit(cache=True)\ndef g():\n    return f()\n"
    )
    (package / "alone.py").write_text("@njit(cache=True)\ndef h():\n    return 2\n")
    return package


def _cache(package: Path, stem: str) -> list[Path]:
    files = [
        package / "__pycache__" / f"{stem}.g-3.py311.nbi",
        package / "__pycache__" / f"{stem}.g-3.py311.1.nbc",
    ]
    for path in files:
        path.write_bytes(b"cached")
    return files


def test_a_callee_edit_drops_its_callers_cache_and_nothing_else(tmp_path) -> None:
    package = _package(tmp_path)
    drop_stale(package)  # records the hashes
    caller, alone = _cache(package, "caller"), _cache(package, "alone")
    assert drop_stale(package) == []  # nothing changed: every cache kept
    assert all(path.exists() for path in caller + alone)
    (package / "callee.py").write_text("def f():\n    return 3\n")
    assert drop_stale(package) == [package / "caller.py"]
    assert not any(path.exists() for path in caller)
    assert all(path.exists() for path in alone)  # its dependencies did not change
    assert drop_stale(package) == []  # recorded again


def test_an_edit_two_imports_away_drops_the_cache(tmp_path) -> None:
    """numba compiles a callee's callees in too: caller → middle → callee."""
    package = _package(tmp_path)
    (package / "middle.py").write_text("from pushctl.callee import f\n\ndef m():\n    return f()\n")
    (package / "caller.py").write_text(
        "from pushctl.middle import m\n\n@njit(cache=True)\ndef g():\n    return m()\n"
    )
    drop_stale(package)
    caller = _cache(package, "caller")
    (package / "callee.py").write_text("def f():\n    return 3\n")
    assert drop_stale(package) == [package / "caller.py"]
    assert not any(path.exists() for path in caller)


def test_an_unrecorded_cache_is_dropped_once(tmp_path) -> None:
    """A cache from before the hashes were recorded cannot be trusted."""
    package = _package(tmp_path)
    caller = _cache(package, "caller")
    assert package / "caller.py" in drop_stale(package)
    assert not any(path.exists() for path in caller)


def test_the_packages_kernel_files_and_what_they_compile_in() -> None:
    files = {path.relative_to(PACKAGE).as_posix(): {d.name for d in deps}
             for path, deps in kernel_files().items()}  # fmt: skip
    assert files["contact/compiled/step.py"] >= {"assembly.py", "pivoting.py", "algebra.py"}
    assert files["contact/compiled/step_end.py"] >= {"arm_kernels.py"}
    # a module imported as a name of its package (``from pkg import module``) counts too
    assert files["contact/compiled/friction_field.py"] == set()
    assert "contact/ground_field.py" not in files  # it calls kernels, defines none
    assert "kernel_cache.py" not in files


def test_every_form_of_import_is_followed(tmp_path) -> None:
    package = _package(tmp_path)
    (package / "sub").mkdir()
    (package / "sub" / "__init__.py").write_text("")
    (package / "sub" / "callee.py").write_text("def f():\n    return 1\n")
    for line in ("from pushctl.sub import callee", "import pushctl.sub.callee",
                 "from .sub.callee import f"):  # fmt: skip
        (package / "caller.py").write_text(f"{line}\n\n@njit(cache=True)\ndef g():\n    return 1\n")
        deps = kernel_files(package)[package / "caller.py"]
        assert package / "sub" / "callee.py" in deps, line
