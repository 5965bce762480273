"""``python -m benchmarks.compare_commits evaluate``: the command it times, what it compares,
and its arguments."""

from __future__ import annotations

from pathlib import Path

from benchmarks.commits.evaluate import body, command, main, same_outputs


def test_the_timed_command_is_the_reproduce_evaluation_with_fewer_trials(tmp_path: Path) -> None:
    policies = [tmp_path / "a.pt", tmp_path / "b.pt"]
    args = command(2, 1, tmp_path / "out", policies)
    assert args[:3] == ["-m", "pushctl.cli", "evaluate"]
    joined = " ".join(args)
    assert "--trials 2 --workers 1 --plant all --seed 0" in joined
    assert f"--policy {policies[0]} --policy {policies[1]}" in joined


def test_the_outputs_compare_after_their_made_by_line(tmp_path: Path) -> None:
    for name, line in (("one", "commit aaa"), ("two", "commit bbb")):
        (tmp_path / name).mkdir()
        for file in ("trials.csv", "steps.csv"):
            (tmp_path / name / file).write_text(f"# made by: {line}\na,b\n1,2\n")
    assert body(tmp_path / "one") == body(tmp_path / "two")
    (tmp_path / "two" / "steps.csv").write_text("# made by: commit bbb\na,b\n1,3\n")
    assert body(tmp_path / "one") != body(tmp_path / "two")


def test_a_column_this_tree_adds_is_left_out_and_every_other_value_compared() -> None:
    reference = (b"a,b\n1,2.50\n", b"s\n7\n")
    assert same_outputs((b"a,new,b\n1,9,2.50\n", b"s\n7\n"), reference)
    assert not same_outputs((b"a,new,b\n1,9,2.5\n", b"s\n7\n"), reference)  # text differs
    assert not same_outputs((b"a,new\n1,9\n", b"s\n7\n"), reference)  # b is missing
    assert not same_outputs((b"a,b\n1,2.50\n", b"s\n8\n"), reference)


def test_bad_arguments_are_one_line_errors(capsys) -> None:
    assert main(["--against", "HEAD", "--repeats", "0"]) == 2
    assert main(["--against", "HEAD", "--workers", "9"]) == 2
    assert main(["--against", "no-such-commit", "--trials", "1"]) == 2
    err = capsys.readouterr().err.splitlines()
    assert err[0] == "error: --repeats must be an integer >= 1, got 0"
    assert err[1].startswith("error: --workers must be an integer in 1")
    assert err[2].startswith("error: --against no-such-commit: cannot unpack it")
    assert len(err) == 3
