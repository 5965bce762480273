"""``python -m benchmarks.slip_loop``: bad arguments and an existing output are one-line
errors; a one-push study measures what the setting changes."""

from __future__ import annotations

import pytest

from benchmarks.slip_loop import CHAOS, main, study
from pushctl.contact.world import MAX_SLIP_ITERATIONS


@pytest.mark.parametrize(
    "argv", [["--pushes", "0"], ["--iterations", "6,-1"], ["--iterations", "a"]]
)
def test_bad_arguments_are_one_line_errors(capsys, argv) -> None:
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: --pushes must be") and err.count("\n") == 1


def test_an_unknown_environment_is_a_one_line_error(capsys) -> None:
    assert main(["--env", "Push-v1"]) == 2
    err = capsys.readouterr().err
    assert err == "error: --env must be one of training, push-v0, got 'Push-v1'\n"


def test_an_existing_output_is_refused(capsys, tmp_path) -> None:
    out = tmp_path / "study.csv"
    out.write_text("kept\n")
    assert main(["--pushes", "1", "--out", str(out)]) == 2
    assert "--force" in capsys.readouterr().err
    assert out.read_text() == "kept\n"


@pytest.mark.parametrize("environment", ["training", "push-v0"])
def test_one_push_study_counts_fewer_solves_with_a_shorter_loop(environment) -> None:
    table = study(1, [MAX_SLIP_ITERATIONS, 0], environment)
    table = table.set_index(["gate", "slip_iterations"])
    for gate in ("shut", "open"):
        default, none = table.loc[(gate, MAX_SLIP_ITERATIONS)], table.loc[(gate, 0)]
        assert default["time_ratio"] == 1.0 and default["final_distance_mm"] == 0.0
        assert none["solves_per_step"] < default["solves_per_step"]
    # The 1 nm nudge moves a push with the base law alone by a trace (random actions
    # amplify it by far more: the reason the bench reports it). With the step's algebra
    # by loops this push's end moves 0.036 mm (8 pushes: 0.0045 mm on average).
    assert 0.0 < table.loc[("shut", CHAOS), "final_distance_mm"] < 0.1
