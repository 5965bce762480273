"""The transfer table (studies.mujoco_transfer): mujoco means and RL/PD beside sim and proxy."""

import math

import pandas as pd
import pytest

from studies import mujoco_transfer as transfer


def _trials(path):
    rows = []
    for trial in range(3):
        for controller, scale in (("pd", 1.0), ("rl", 2.0)):
            rows.append(
                {
                    "object": "cube",
                    "profile": "constant",
                    "plant": "mujoco",
                    "controller": controller,
                    "trial": trial,
                    "translation_error_pct": scale * (0.1 + 0.1 * trial),
                    "angle_error_pct": scale * 0.5,
                    "force_error": scale * 0.03,
                    "gate_open_fraction": 0.0 if controller == "pd" else 0.25,
                    "contact_loss_fraction": 0.0,
                }
            )
    path.write_text("# made by: a test; x\n" + pd.DataFrame(rows).to_csv(index=False))
    return path


def test_mujoco_means_and_ratios(tmp_path):
    trials = pd.read_csv(_trials(tmp_path / "trials.csv"), comment="#")
    table = transfer.mujoco_table(trials)
    row = table.iloc[0]
    assert row["translation_error_pd"] == pytest.approx(0.2)
    assert row["translation_error_rl"] == pytest.approx(0.4)
    assert row["gate_rl"] == pytest.approx(0.25)
    assert int(row["n"]) == 3


def test_block_puts_mujoco_beside_the_shipped_tables(tmp_path):
    block = transfer.transfer_markdown(_trials(tmp_path / "trials.csv"))
    line = next(x for x in block.splitlines() if x.startswith("| cube | constant"))
    cells = [c.strip() for c in line.strip("|").split("|")]
    shipped = transfer.shipped_ratios()
    sim = shipped[(shipped["object"] == "cube") & (shipped["profile"] == "constant")].iloc[0]
    assert cells[8] == f"{sim['translation_sim']:.3g} / 2"
    assert cells[10].endswith("/ 2")
    assert math.isfinite(sim["force_proxy"])


def test_report_tables_gain_mujoco_columns_only_with_mujoco_rows():
    from pushctl.report.tables import table3, table4

    shipped = pd.read_csv("results/evaluation/trials.csv", comment="#")
    shipped = shipped[shipped["plant"] != "mujoco"]  # the shipped run has MuJoCo rows: drop them
    assert not any(c.endswith("_mujoco") for c in table4(shipped).values.columns)
    cube = shipped[(shipped["object"] == "cube") & (shipped["profile"] == "constant")]
    mujoco = cube[cube["plant"] == "sim"].assign(plant="mujoco")
    mujoco = mujoco.assign(translation_error_pct=3.0 * mujoco["translation_error_pct"])
    both = pd.concat([shipped, mujoco])
    t3, t4 = table3(both).values, table4(both).values
    row = t3[(t3["object"] == "cube") & (t3["profile"] == "constant")].iloc[0]
    assert row["translation_error_pd_mujoco"] == pytest.approx(3.0 * row["translation_error_pd"])
    assert "force_error_rl_mujoco" in t4.columns and "torque_error_pd_mujoco_ci95" in t4.columns
