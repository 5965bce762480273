"""``python -m pushctl.bench.profile_env``: bad arguments are one-line errors."""

from __future__ import annotations

from pushctl.bench.profile_env import main


def test_no_pushes_is_a_one_line_error(capsys) -> None:
    assert main(["shut", "--pushes", "0"]) == 2
    assert capsys.readouterr().err == "error: --pushes and --top must be integers >= 1\n"
