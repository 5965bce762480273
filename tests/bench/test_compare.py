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


def test_the_ratio_is_the_median_of_the_pairs_so_a_drift_between_pairs_cancels() -> None:
    """Both trees equally fast; the machine twice as slow for the last pairs, and for one
    child of the third: the trees' medians (20 against 10) compare slow children with fast
    ones, each pair's ratio is 1 but that one."""
    import statistics

    from pushctl.bench.compare import paired_ratio

    this = [10.0, 10.0, 20.0, 20.0, 20.0]
    reference = [10.0, 10.0, 10.0, 20.0, 20.0]
    assert statistics.median(this) / statistics.median(reference) == 2.0
    assert paired_ratio(this, reference) == 1.0
    assert paired_ratio([9.0, 18.0, 27.0], [10.0, 20.0, 30.0]) == 0.9
