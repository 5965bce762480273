"""The PD sweep (studies/pd_sweep.py): the PD baseline on many drawn scenarios."""

import pytest

from pushctl.control import PDGains


def test_pd_sweep_rows_and_summary():
    from studies.pd_sweep import run_sweep, summary

    gains = PDGains(kp=30.0, kv=300.0, kx_linear=42.0, kx_angular=42.0)
    frame = run_sweep(2, "training", "sim", gains, ("cube",), ("chirp",), duration=1.0)
    assert list(frame["seed"]) == [0, 1]
    assert frame["mu_contact"].between(0.30, 0.50).all()  # the sim ranges
    assert (frame["goal_theta_deg"].abs() >= 10.0).all()
    table = summary(frame)
    assert (
        table.loc[("cube", "chirp"), "translation_error_pct"]
        == frame["translation_error_pct"].mean()
    )
    assert 0.0 <= table.loc[("cube", "chirp"), "episodes_slip_over_1pct"] <= 1.0


def test_pd_sweep_provenance_names_its_arguments_not_its_output():
    """Two sweeps into two places write the same first line (docs/design.md §8)."""
    import argparse

    from studies.pd_sweep import sweep_command

    args = argparse.Namespace(plant="proxy", seeds=3, stream="tuning", out="elsewhere.csv")
    command = sweep_command(args)
    assert command == "python -m studies.pd_sweep --plant proxy --seeds 3 --stream tuning"
    assert "elsewhere" not in command


def test_pd_sweep_refuses_an_existing_output_before_it_works(tmp_path, capsys):
    """The sweep writes over a file only with --force, and refuses before any episode runs."""
    from studies import pd_sweep

    out = tmp_path / "sweep.csv"
    out.write_text("kept\n")
    with pytest.raises(SystemExit) as exit_info:
        pd_sweep.main(["--seeds", "1", "--out", str(out)])
    assert exit_info.value.code == 2
    error = capsys.readouterr().err
    assert error.count("\n") == 1 and "--force" in error and str(out) in error
    assert out.read_text() == "kept\n"
