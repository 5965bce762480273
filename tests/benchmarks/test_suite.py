"""``make bench`` (``python -m benchmarks.suite``): it refuses to overwrite a CSV it was not
told to, and writes the performance page's table only when given the page."""

from __future__ import annotations

from pathlib import Path

import pytest

from benchmarks import suite as bench
from benchmarks.performance_page import BEGIN, END


def test_bench_refuses_an_existing_csv(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture
) -> None:
    out = tmp_path / "bench.csv"
    out.write_text("shipped\n")
    ran: list[int] = []

    def tiny(repeats: int) -> list[dict]:
        ran.append(repeats)
        return [{"name": "x", "value": 1.0, "unit": "µs", "note": "test"}]

    monkeypatch.setattr(bench, "run_benchmarks", tiny)
    assert bench.main(["--out", str(out), "--repeats", "1"]) == 2
    error = capsys.readouterr().err.strip()
    assert error.startswith("error:") and "--force" in error and len(error.splitlines()) == 1
    assert out.read_text() == "shipped\n" and ran == []  # refused before any timing
    assert bench.main(["--out", str(out), "--repeats", "1", "--force"]) == 0
    assert ran == [1] and out.read_text().startswith("# made by:")


def test_the_page_s_table_is_rewritten_only_when_asked(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture
) -> None:
    rows = [
        {"name": "world step arm+cube [ours]", "value": 30.0, "unit": "us", "note": ""},
        {"name": "world step arm+cube [mujoco]", "value": 20.0, "unit": "us", "note": ""},
    ]
    monkeypatch.setattr(bench, "run_benchmarks", lambda repeats: rows)
    page = tmp_path / "performance.md"
    page.write_text(f"# Performance\n\n{BEGIN}\nold\n{END}\n\nWhy.\n")
    assert bench.main(["--out", str(tmp_path / "a.csv"), "--repeats", "1"]) == 0
    assert "old" in page.read_text()  # not asked
    assert (
        bench.main(["--out", str(tmp_path / "b.csv"), "--repeats", "1", "--page", str(page)]) == 0
    )
    text = page.read_text()
    assert "old" not in text and "| world step arm+cube | 30.0 | 20.0 | 1.50 | — |" in text
    assert text.startswith("# Performance\n") and text.endswith("\n\nWhy.\n")
    missing = tmp_path / "none.md"
    assert bench.main(["--out", str(tmp_path / "c.csv"), "--page", str(missing)]) == 2
    assert capsys.readouterr().err.startswith(f"error: --page {missing} is not a file")
