"""The provenance line of a script that builds it from its own command line."""

import sys

from pushctl.files.provenance import provenance_line, recorded_argv


def test_recorded_argv_drops_where_files_go_and_force_with_their_values():
    argv = ["--profile", "--out", "results/bench.csv", "--force", "--repeats", "7",
            "--plot=fig.png", "--workers", "2", "--core", "0"]  # fmt: skip
    assert recorded_argv(argv) == ["--profile", "--repeats", "7", "--core", "0"]


def test_an_option_that_only_starts_like_a_dropped_one_is_kept():
    assert recorded_argv(["--outer", "1", "--forced"]) == ["--outer", "1", "--forced"]


def test_two_runs_into_two_places_write_the_same_line(monkeypatch):
    lines = []
    for out in ("a.csv", "elsewhere/b.csv"):
        monkeypatch.setattr(sys, "argv", ["bench.py", "--repeats", "3", "--out", out, "--force"])
        lines.append(provenance_line())
    assert lines[0] == lines[1]
    assert lines[0].startswith("# made by: bench.py --repeats 3; pushctl ")
