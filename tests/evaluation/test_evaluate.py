"""The evaluation's core: the seed scheme, pairing (a shut gate is PD-only to the bit, an
acting policy changes the push of the same scenario), the per-step table agreeing with the
metrics, the outputs, and bad input."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from pushctl.control.feedback import FeedbackGains
from pushctl.controllers.feedback import feedback_config
from pushctl.episode.metrics import EpisodeMetrics, compute_metrics
from pushctl.episode.ranges import load_ranges
from pushctl.episode.scenario import STREAMS
from pushctl.episode.unknowns import unknowns_rng
from pushctl.errors import ConfigError
from pushctl.evaluation.columns import STEP_COLUMNS, TRIAL_COLUMNS, UNKNOWN_COLUMNS
from pushctl.evaluation.evaluate import (
    STEPS_FILE,
    TRIALS_FILE,
    evaluate,
    load_evaluation_policy,
    summary,
    write_evaluation,
)
from pushctl.evaluation.trials import SEEDS_PER_EVALUATION, TrialSpec, step_quantities
from pushctl.rl.config import DDPGConfig
from pushctl.rl.ddpg import DDPGAgent
from pushctl.rl.policy import write_policy
from pushctl.task.env import PushEnv
from pushctl.task.env_config import EnvConfig
from pushctl.task.spaces import observation_entries, scales

DURATION = 2.0
"""Push duration of the test policies [s]: 200 steps, a fraction of a second per push."""


def policy_file(tmp_path: Path, gate_threshold: float, n_obs: int | None = None) -> Path:
    """An untrained actor with large outputs, saved with a short push."""
    entries = observation_entries(2, reference_offset=True)
    n = n_obs if n_obs is not None else len(entries)
    agent = DDPGAgent(
        n,
        3,
        DDPGConfig(hidden=(8, 8), actor_final_init=0.5),
        seed=0,
        obs_scale=scales(entries)[:n] if n <= len(entries) else None,
    )
    path = tmp_path / f"policy_{gate_threshold}_{n}.pt"
    # the prongs where the approach landed them, as PD-only's (a shut gate is then PD-only)
    env = EnvConfig(duration=DURATION, gate_threshold=gate_threshold, landing="believed")
    write_policy(path, agent.actor_state(), env, "# made by: test")
    return path


def _spec(**kwargs) -> TrialSpec:
    options = {
        "objects": ("cube",),
        "profiles": ("trapezoid",),
        "plants": ("sim",),
        "controllers": ("pd", "rl"),
        "trials": 1,
    }
    return TrialSpec(**{**options, **kwargs})


def test_the_seed_scheme_gives_disjoint_scenarios_per_evaluation_seed() -> None:
    first, second = TrialSpec(seed=0, trials=50), TrialSpec(seed=1, trials=50)
    seeds = {job.seed for job in first.jobs()}
    assert seeds == set(range(50))  # seed 0: trial i is `pushctl simulate --seed i`'s push
    assert seeds.isdisjoint(job.seed for job in second.jobs())
    last = TrialSpec(seed=0, trials=SEEDS_PER_EVALUATION).scenario_seed(SEEDS_PER_EVALUATION - 1)
    assert last < second.scenario_seed(0)
    jobs = first.jobs()
    assert len(jobs) == 2 * 3 * 2 * 50 and first.n_episodes == 3 * len(jobs)  # pd, feedback, rl
    # every cell and plant of one trial pushes the same scenario seed
    assert {(j.seed) for j in jobs if j.trial == 7} == {7}


@pytest.mark.parametrize(
    ("options", "fragment"),
    [
        ({"objects": ("sphere",)}, "cube, wedge"),
        ({"profiles": ("sine",)}, "constant, trapezoid, chirp"),
        ({"plants": ("real",)}, "sim, proxy"),
        ({"controllers": ("ppo",)}, "pd, feedback, rl"),
        ({"objects": ()}, "(none)"),
        ({"plants": ("sim", "sim")}, "named once"),
        ({"trials": 0}, "--trials"),
        ({"trials": SEEDS_PER_EVALUATION + 1}, "--trials"),
        ({"trials": True}, "--trials"),
        ({"seed": -1}, "--seed"),
    ],
)
def test_a_bad_spec_is_one_line(options: dict, fragment: str) -> None:
    with pytest.raises(ConfigError, match="accepted|must be|once") as caught:
        TrialSpec(**options)
    assert fragment in str(caught.value) and "\n" not in str(caught.value)


def test_a_policy_behind_a_shut_gate_equals_pd_only(tmp_path: Path) -> None:
    policy = load_evaluation_policy(policy_file(tmp_path, gate_threshold=1.0))
    result = evaluate(_spec(trials=2), policy)
    trials = result.trials
    assert list(trials.columns) == [*TRIAL_COLUMNS, *EpisodeMetrics.__dataclass_fields__]
    assert list(trials["controller"]) == ["pd", "pd", "rl", "rl"]
    assert list(trials["trial"]) == [0, 1, 0, 1]
    metrics = list(EpisodeMetrics.__dataclass_fields__)
    pd_rows = trials[trials["controller"] == "pd"]
    rl_rows = trials[trials["controller"] == "rl"]
    np.testing.assert_array_equal(pd_rows[metrics].to_numpy(), rl_rows[metrics].to_numpy())
    assert (trials["gate_open_fraction"] == 0.0).all()
    assert pd_rows["mu_ground"].iloc[0] != pd_rows["mu_ground"].iloc[1]  # two drawn plants
    for _, row in trials.iterrows():  # the plant unknowns of each trial's seed, as drawn
        drawn = load_ranges().unknowns("sim").draw(unknowns_rng(row["seed"], STREAMS["evaluation"]))
        assert row[list(UNKNOWN_COLUMNS)].to_dict() == pytest.approx(drawn.as_dict(2))
    steps = result.steps
    assert len(steps) == 2 * (round(DURATION / 0.01) + 1)
    pd_steps = steps[steps["controller"] == "pd"][list(STEP_COLUMNS)].to_numpy()
    rl_steps = steps[steps["controller"] == "rl"][list(STEP_COLUMNS)].to_numpy()
    np.testing.assert_array_equal(pd_steps, rl_steps)


def test_an_acting_policy_changes_the_push_of_the_same_scenario(tmp_path: Path) -> None:
    policy = load_evaluation_policy(policy_file(tmp_path, gate_threshold=0.0))
    trials = evaluate(_spec(objects=("wedge",), profiles=("constant",)), policy).trials
    pd_row, rl_row = trials.iloc[0], trials.iloc[1]
    same = ["seed", "goal_dx", "goal_dy", "goal_dtheta", "mu_ground", "mu_contact", "object_mass"]
    assert list(pd_row[same]) == list(rl_row[same])
    assert rl_row["translation_error_pct"] != pd_row["translation_error_pct"]
    assert pd_row["gate_open_fraction"] == 0.0 and rl_row["gate_open_fraction"] > 0.9
    # PD-only alone draws the same scenario and pushes it the same way
    alone = evaluate(_spec(objects=("wedge",), profiles=("constant",), controllers=("pd",)),
                     env_config=policy.env).trials  # fmt: skip
    pd.testing.assert_frame_equal(alone, trials.iloc[:1], check_exact=True)


@pytest.mark.parametrize("plant", ["sim", "proxy"])
def test_the_per_step_means_agree_with_the_trial_metrics(tmp_path: Path, plant: str) -> None:
    """Means over steps 1 … N of the per-step means over trials are the means over trials
    of the per-trial metrics (on the proxy both use the camera's poses)."""
    policy = load_evaluation_policy(policy_file(tmp_path, gate_threshold=0.0))
    spec = _spec(profiles=("chirp",), plants=(plant,), trials=2)
    result = evaluate(spec, policy)
    for controller in ("pd", "rl"):
        rows = result.trials[result.trials["controller"] == controller]
        steps = result.steps[result.steps["controller"] == controller]
        assert list(steps["step"]) == list(range(len(steps)))
        push = steps.iloc[1:]
        for step_column, metric, scale in (
            ("force_error", "force_error", 1.0),
            ("torque_error", "torque_error", 1.0),
            ("angle_error_deg", "angle_error_deg", 1.0),
        ):
            assert push[step_column].mean() == pytest.approx(scale * rows[metric].mean(), 1e-9)
        final = steps.iloc[-1]
        assert final["translation_error_mm"] == pytest.approx(
            1e3 * rows["final_position_error"].mean(), abs=1e-9
        )
        # the plan ends at the goal: chord [mm] and |Δθ| [deg], whatever the turn's sign
        chord = 1e3 * np.hypot(rows["goal_dx"], rows["goal_dy"]).mean()
        assert final["translation_des_mm"] == pytest.approx(chord, 1e-9)
        assert final["angle_des_deg"] == pytest.approx(
            np.degrees(rows["goal_dtheta"].abs()).mean(), 1e-9
        )
        assert steps.iloc[0]["translation_des_mm"] == 0.0
        assert final["t"] == pytest.approx(DURATION)


def test_the_outputs_read_back_with_their_provenance(tmp_path: Path) -> None:
    policy = load_evaluation_policy(policy_file(tmp_path, gate_threshold=0.0))
    result = evaluate(_spec(objects=("cube", "wedge"), plants=("sim", "proxy")), policy)
    out = tmp_path / "deep" / "out"
    write_evaluation(out, result, "# made by: a test")
    for name, frame in ((TRIALS_FILE, result.trials), (STEPS_FILE, result.steps)):
        assert (out / name).read_text().startswith("# made by: a test\n")
        back = pd.read_csv(out / name, comment="#")
        assert list(back.columns) == list(frame.columns) and len(back) == len(frame)
        numbers = frame.select_dtypes("number").columns
        relative = 1e-8 if name == TRIALS_FILE else 1e-5  # 9 and 6 significant figures
        np.testing.assert_allclose(back[numbers], frame[numbers], rtol=relative, atol=1e-12)
    table = summary(result.trials)
    assert list(table.index) == [
        ("cube", "trapezoid", "sim"),
        ("cube", "trapezoid", "proxy"),
        ("wedge", "trapezoid", "sim"),
        ("wedge", "trapezoid", "proxy"),
    ]
    assert table.loc[("cube", "trapezoid", "sim"), ("force_error", "rl")] == pytest.approx(
        result.trials.query("object == 'cube' and plant == 'sim' and controller == 'rl'")[
            "force_error"
        ].iloc[0]
    )
    assert result.redrawn == 0  # docs/design.md §7's ranges: every goal feasible
    assert sorted(result.trials["redrawn"].unique()) == [0]


def test_bad_policies_and_workers_are_refused(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="no policy file"):
        load_evaluation_policy(tmp_path / "none.pt")
    (tmp_path / "bad.pt").write_bytes(b"garbage")
    with pytest.raises(ConfigError, match="not a policy file or is cut short"):
        load_evaluation_policy(tmp_path / "bad.pt")
    with pytest.raises(ConfigError, match="incompatible: its actor takes 14 observations"):
        load_evaluation_policy(policy_file(tmp_path, 0.0, n_obs=14))
    with pytest.raises(ConfigError, match="need a policy"):
        evaluate(_spec())
    with pytest.raises(ConfigError, match="need a policy"):
        evaluate(TrialSpec())  # every controller by default, rl among them
    for workers in (0, 9):
        with pytest.raises(ConfigError, match="--workers"):
            evaluate(_spec(controllers=("pd",)), workers=workers)


def test_a_zero_feedback_law_is_the_pd_from_its_landing_and_rl_rows_name_the_policy_seed(
    tmp_path: Path,
) -> None:
    """k = k_i = 0 and no contact seeking: the law's action is zero, the reference path adds
    nothing but the re-landing's offset, and the push is the PD's from the re-landed start
    to the bit (PD-only's own starts where the approach landed); the rl row carries the
    policy's training seed, the others none."""
    path = tmp_path / "policy.pt"
    agent = DDPGAgent(
        len(observation_entries(2, reference_offset=True)), 3, DDPGConfig(hidden=(4, 4)), seed=0
    )
    env = EnvConfig(duration=DURATION, gate_threshold=0.0)
    write_policy(path, agent.actor_state(), env, "# made by: x; seed 5 (training stream)")
    spec = _spec(controllers=("pd", "feedback", "rl"), plants=("sim", "proxy"))
    zero = FeedbackGains(0.0, 0.0, seek_rate=0.0)
    result = evaluate(spec, load_evaluation_policy(path), controller_gains={"feedback": zero})
    trials = result.trials
    assert list(trials["controller"]) == ["pd", "feedback", "rl"] * 2
    assert [None if pd.isna(s) else s for s in trials["policy_seed"]] == [None, None, 5] * 2
    metrics = list(EpisodeMetrics.__dataclass_fields__)
    steps = result.steps
    for plant in ("sim", "proxy"):
        rows = trials[trials["plant"] == plant].set_index("controller")
        law_env = PushEnv(feedback_config(replace(env, plant=plant, stream="evaluation")))
        options = {"object": "cube", "profile": "trapezoid", "scenario_seed": 0}
        law_env.reset(options=options)
        assert law_env.episode is not None
        relanded = law_env.episode.finish()
        assert list(rows.loc["feedback", metrics]) == list(
            compute_metrics(relanded).as_dict().values()
        )
        assert abs(rows.loc["feedback", "landed_offset"]) < 0.5 * abs(
            rows.loc["pd", "landed_offset"]
        )
        cell = steps[steps["plant"] == plant]
        np.testing.assert_array_equal(
            cell[cell["controller"] == "feedback"][list(STEP_COLUMNS)].to_numpy(),
            step_quantities(relanded),
        )
