"""``python -m pushctl.bench.compare``: its child script and its arguments (the timing itself
runs in ``make bench``)."""

from __future__ import annotations

from pushctl.bench.compare import _CHILD, METRICS, main


def test_the_child_script_compiles_and_reports_every_metric() -> None:
    compile(_CHILD, "<bench child>", "exec")
    for metric in METRICS:
        if metric != "cold MLCP, ProxQP path of the reference":  # derived by the parent
            assert f'"{metric}"' in _CHILD, metric


def test_a_core_the_machine_lacks_is_a_one_line_error(capsys) -> None:
    assert main(["--core", "4096", "--repeats", "1"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: --core must be a core of this machine") and err.count("\n") == 1
