"""The table ``make bench`` writes into docs/performance.md (benchmarks.performance_page)."""

from __future__ import annotations

from pathlib import Path

from benchmarks.performance_page import BEGIN, END, bench_block, replace_block

ROOT = Path(__file__).resolve().parents[2]
ROWS = [
    {"name": "solve_box_mlcp warm", "value": 3.21, "unit": "us", "note": "n = 10 rows"},
    {"name": "world step arm+cube [ours]", "value": 30.0, "unit": "us", "note": "one core"},
    {"name": "world step arm+cube [mujoco]", "value": 20.0, "unit": "us", "note": "one core"},
    {"name": "world step arm+cube ours/mujoco", "value": 1.5, "unit": "1", "note": "ratio"},
    {"name": "world step arm+cube [mujoco mj_step alone]", "value": 12.0, "unit": "us",
     "note": "raw"},
    {"name": "closed-loop step [ours]", "value": 80.0, "unit": "us", "note": ""},
    {"name": "closed-loop step [mujoco]", "value": 100.0, "unit": "us", "note": ""},
    {"name": "rl DDPG updates/s", "value": 1234.5, "unit": "1/s", "note": "a | b"},
]  # fmt: skip


def test_the_engines_stand_side_by_side_and_the_rest_below() -> None:
    block = bench_block(ROWS, "x86_64, 2 cores, one used", "2026-01-02")
    assert block.startswith(BEGIN) and block.rstrip().endswith(END)
    assert "| world step arm+cube | 30.0 | 20.0 | 1.50 | 12.0 |" in block
    assert "| closed-loop step | 80.0 | 100.0 | 0.80 | — |" in block
    assert "| solve_box_mlcp warm | 3.21 | us | n = 10 rows |" in block
    assert "| rl DDPG updates/s | 1234 | 1/s | a / b |" in block  # a | would split the cell
    assert "ours/mujoco" not in block and "[ours]" not in block


def test_only_the_generated_block_is_replaced() -> None:
    page = f"# Performance\n\nBefore.\n\n{BEGIN}\nold numbers\n{END}\n\nAfter.\n"
    new = replace_block(page, f"{BEGIN}\nnew numbers\n{END}\n")
    assert new == f"# Performance\n\nBefore.\n\n{BEGIN}\nnew numbers\n{END}\n\nAfter.\n"
    assert replace_block("# Page\n", "block\n") == "# Page\n\nblock\n"


def test_the_performance_page_has_the_block_make_bench_fills() -> None:
    page = (ROOT / "docs" / "performance.md").read_text()
    assert page.count(BEGIN) == 1 and page.count(END) == 1
