"""``python -m benchmarks.profile_env``: bad arguments are one-line errors."""

from __future__ import annotations

from dataclasses import replace

from benchmarks.profile_env import environment_config, main
from pushctl.rl.presets import load_preset


def test_no_pushes_is_a_one_line_error(capsys) -> None:
    assert main(["shut", "--pushes", "0"]) == 2
    assert capsys.readouterr().err == "error: --pushes and --top must be integers >= 1\n"


def test_train_mode_pushes_the_paper_presets_environment() -> None:
    """``train`` is what a ``paper`` run's collectors step: its base law and action repeat."""
    config = environment_config("train")
    assert config == load_preset("paper").env
    assert config.base_law == "feedback"
    assert config.action_repeat == 10


def test_gate_modes_differ_only_in_the_gate() -> None:
    shut, opened = environment_config("shut"), environment_config("open")
    assert (shut.gate_threshold, opened.gate_threshold) == (1.0, 0.0)
    assert replace(shut, gate_threshold=0.0) == opened
    assert environment_config("feedback").base_law == "none"


def test_sampled_runs_the_pushes_without_cprofile(capsys) -> None:
    """One push, run twice (a 2000-step push is the shortest there is: about 0.5 s)."""
    assert main(["shut", "--pushes", "1", "--sampled"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("shut: ") and "(kernels loaded)" in out
    assert "cProfile" not in out and "function calls" not in out
