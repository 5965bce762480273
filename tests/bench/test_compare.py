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


def test_the_cold_problems_are_recorded_from_every_step_that_left_the_warm_active_set() -> None:
    """The recording makes each step in parts (the compiled step, slip_step, would solve
    most cold steps inside one call, unseen): random actions send many steps to the cold
    path; afterwards the world steps in one call again."""
    import pushctl.contact.substep as substep_module
    from pushctl.bench.compare import record_cold_problems

    compiled_step = substep_module.SubstepSolver._compiled_step
    problems = record_cold_problems(steps=300)
    # 300 random-action steps: about 40 % leave the warm active set; a new contact set
    # alone (what the recording saw when the compiled step was left in place) about 2 %
    assert len(problems) > 60
    assert all(warm is None or warm.shape == b.shape for _, b, *_, warm in problems)
    assert substep_module.SubstepSolver._compiled_step is compiled_step
