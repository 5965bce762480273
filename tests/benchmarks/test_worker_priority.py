"""``python -m benchmarks.worker_priority``: bad arguments are one-line errors, and it
refuses to run inside a Ray session it did not start (it starts Ray with each niceness)."""

from __future__ import annotations

import pytest

from benchmarks.worker_priority import main, slowdowns


@pytest.mark.parametrize("argv", [["--work", "0"], ["--repeats", "0"], ["--work", "100"]])
def test_bad_arguments_are_one_line_errors(capsys, argv) -> None:
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("worker_priority: --work must be") and err.count("\n") == 1


def test_it_will_not_run_inside_another_ray_session(ray_local: None) -> None:
    with pytest.raises(RuntimeError, match="run on its own"):
        slowdowns([0], 0.01, 1)
