"""The kernels' warm-up: the first command says it compiles when numba's cache is cold, and
``make install``'s :func:`~pushctl.cli.warm.warm` fills the cache."""

from __future__ import annotations

import io
from pathlib import Path

import pytest
from rich.console import Console

from pushctl.cli import warm

KERNEL_FILE = "from numba import njit\n\n\n@njit(cache=True)\ndef twice(x):\n    return 2 * x\n"


def _package(root: Path) -> Path:
    (root / "sub").mkdir(parents=True)
    (root / "sub" / "kernels.py").write_text(KERNEL_FILE)
    (root / "plain.py").write_text("X = 1\n")
    return root


def test_a_kernel_file_without_its_cache_is_cold(tmp_path, monkeypatch):
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    package = _package(tmp_path / "pkg")
    assert warm.cache_is_cold(package)
    (package / "sub" / "__pycache__").mkdir()
    (package / "sub" / "__pycache__" / "kernels.twice-4.py311.nbi").write_bytes(b"")
    assert not warm.cache_is_cold(package)


def test_the_note_is_said_only_when_cold(monkeypatch):
    for cold, said in ((True, warm.COMPILING), (False, "")):
        monkeypatch.setattr(warm, "cache_is_cold", lambda cold=cold: cold)
        out = io.StringIO()
        warm.note_if_cold(Console(file=out, width=40))
        assert out.getvalue().strip() == said


@pytest.mark.slow
def test_this_tree_is_warm_after_warm():
    """Slow in a fresh clone (a minute of compiling); seconds once the cache is filled."""
    warm.warm()
    assert not warm.cache_is_cold()
