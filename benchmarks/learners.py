"""Our DDPG and TD3 beside stable-baselines3's DDPG, TD3 and SAC on standard tasks, one budget
each, in one run (docs/learner-check.md): does the learner reach what a reference learner reaches
where the answer is known?

Run from the checkout's root as ``python -m benchmarks.learners [--out
docs/learner-check.csv] [--tasks Pendulum-v1,InvertedPendulum-v5] [--seeds 0,1,2]
[--learners ours-ddpg,ours-td3,sb3-ddpg,sb3-td3,sb3-sac] [--force]`` (``make bench-learners``; an
existing --out file is replaced only with ``--force``). A benchmark, not a test: the full
run trains 30 learners on one core and prints its wall time.

Every learner of a task gets the same :class:`Budget`: environment steps, warm-up steps
(uniform random actions, SB3's ``learning_starts`` rule, then one gradient update per
step), batch, replay size, network widths, one learning rate for actor and critic, γ, τ and
Gaussian exploration noise of one standard deviation in normalised action units (TD3's
rule; SAC explores with its own entropy instead). Ours is
:class:`pushctl.rl.ddpg.DDPGAgent` driven through its public loop (act, observe,
updates_due, update, reset_noise) with plain DDPG settings (no prior, no action penalty,
observations unscaled, the actor's output layer at ±3e-3); OU noise with θ = 1 and dt = 1
is white Gaussian noise of std σ. ``ours-td3`` adds twin critics, target smoothing (0.2,
clipped at 0.5) and an actor update every second step, with the targets moved on that step
only, as SB3's TD3; ``sb3-ddpg`` is SB3's DDPG (its TD3 without them), the like of
``ours-ddpg``. Actions map between the environment's Box and [−1, 1] as SB3 maps them.

Seeds: run ``seed`` resets its training environment with ``seed`` (then unseeded) and seeds
the agent or SB3 model with it; the warm-up's uniform actions of ours come from
``SeedSequence(seed)``. Score of a run: the mean undiscounted return of
:data:`EVAL_EPISODES` deterministic episodes after the budget, on reset seeds
``EVAL_SEED + k``, the same for every learner and disjoint from training seeds (which must
be below :data:`EVAL_SEED`). One torch thread.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from pushctl.errors import ConfigError
from pushctl.files.output_guard import refuse_existing_files
from pushctl.files.provenance import provenance_line, recorded_argv, write_csv
from pushctl.rl.config import DDPGConfig
from pushctl.rl.ddpg import DDPGAgent
from pushctl.rl.networks import configure_torch

EVAL_EPISODES = 10
"""Deterministic evaluation episodes per run."""
EVAL_SEED = 1000
"""Reset seed of the first evaluation episode; episode k uses ``EVAL_SEED + k``."""
LEARNERS = ("ours-ddpg", "ours-td3", "sb3-ddpg", "sb3-td3", "sb3-sac")
REFERENCE = "sb3-td3"
"""The learner whose 95 % interval ours are judged against (the issue's bar); each of ours is
also set beside its own SB3 counterpart (``sb3-ddpg``, ``sb3-td3``)."""
COLUMNS = [
    "task",
    "learner",
    "seed",
    "steps",
    "warmup_steps",
    "eval_episodes",
    "mean_return",
    "std_return",
    "min_return",
    "max_return",
]


@dataclass(frozen=True)
class Budget:
    """What every learner of a task gets (SB3 zoo-like hyper-parameters).

    ``steps`` [env steps] in all, the first ``warmup_steps`` uniform random actions, then
    one gradient update per step; ``hidden`` widths of actor and critic [units];
    ``learning_rate`` of actor and critic (Adam) [1/update]; ``gamma`` per step; ``tau``
    Polyak factor per update; ``noise_std`` exploration std in normalised action units.
    """

    steps: int
    warmup_steps: int
    hidden: tuple[int, ...]
    learning_rate: float
    gamma: float
    batch_size: int = 256
    buffer_size: int = 1_000_000
    tau: float = 0.005
    noise_std: float = 0.1
    eval_episodes: int = EVAL_EPISODES


BUDGETS = {
    # rl-zoo3 td3.yml Pendulum-v1 (buffer 200k there; this budget never fills 20k)
    "Pendulum-v1": Budget(
        steps=20_000, warmup_steps=10_000, hidden=(400, 300), learning_rate=1e-3, gamma=0.98
    ),
    # rl-zoo3's MuJoCo defaults (SB3 SAC's widths); the task is solved in ~15k steps
    "InvertedPendulum-v5": Budget(
        steps=30_000, warmup_steps=5_000, hidden=(256, 256), learning_rate=1e-3, gamma=0.99
    ),
}


def ours_config(budget: Budget, learner: str) -> DDPGConfig:
    """Plain DDPG (``ours-ddpg``) or TD3 (``ours-td3``) with the budget's settings."""
    config = DDPGConfig(
        hidden=budget.hidden,
        actor_lr=budget.learning_rate,
        critic_lr=budget.learning_rate,
        gamma=budget.gamma,
        tau=budget.tau,
        batch_size=budget.batch_size,
        buffer_size=min(budget.buffer_size, budget.steps),
        warmup_steps=budget.warmup_steps,
        updates_per_step=1.0,
        ou_theta=1.0,  # with dt = 1: x = σ·ε, white Gaussian noise
        ou_sigma=budget.noise_std,
        ou_dt=1.0,
        actor_final_init=3e-3,
        action_penalty=0.0,
        prior_weight=0.0,
    )
    if learner == "ours-td3":
        config = replace(config, twin_critics=True, target_noise=0.2, actor_delay=2)
    return config


class BoxScale:
    """Actions between the env's Box [low, high] and [−1, 1], as SB3 maps them."""

    def __init__(self, space: Any) -> None:
        self.low = np.asarray(space.low, dtype=np.float64)
        self.high = np.asarray(space.high, dtype=np.float64)

    def to_env(self, action: np.ndarray) -> np.ndarray:
        """[−1, 1] (act_dim,) → env units (act_dim,), float32."""
        return (self.low + 0.5 * (action + 1.0) * (self.high - self.low)).astype(np.float32)


def evaluate(env: Any, act: Callable[[np.ndarray], np.ndarray], episodes: int) -> np.ndarray:
    """Undiscounted returns (episodes,) of ``act`` (obs → env action), reset seeds
    ``EVAL_SEED + k``."""
    returns = np.zeros(episodes)
    for k in range(episodes):
        obs, _ = env.reset(seed=EVAL_SEED + k)
        done = False
        while not done:
            obs, reward, terminated, truncated, _ = env.step(act(obs))
            returns[k] += float(reward)
            done = terminated or truncated
    return returns


def train_ours(task: str, learner: str, seed: int, budget: Budget) -> Callable:
    """Train our agent; returns its deterministic policy, obs → env action."""
    import gymnasium

    env = gymnasium.make(task)
    box = BoxScale(env.action_space)
    act_dim = int(np.prod(env.action_space.shape))
    obs_dim = int(np.prod(env.observation_space.shape))
    agent = DDPGAgent(obs_dim, act_dim, ours_config(budget, learner), seed=seed)
    uniform = np.random.default_rng(np.random.SeedSequence(seed))
    obs, _ = env.reset(seed=seed)
    agent.reset_noise()
    for step in range(budget.steps):
        if step < budget.warmup_steps:
            action = uniform.uniform(-1.0, 1.0, act_dim)
        else:
            action = agent.act(obs, explore=True)
        next_obs, reward, terminated, truncated, _ = env.step(box.to_env(action))
        agent.observe(obs, action, float(reward), next_obs, bool(terminated))
        for _ in range(agent.updates_due(1)):
            agent.update()
        if terminated or truncated:
            obs, _ = env.reset()
            agent.reset_noise()
        else:
            obs = next_obs
    env.close()
    return lambda obs: box.to_env(agent.policy_action(obs))


def train_sb3(task: str, learner: str, seed: int, budget: Budget) -> Callable:
    """Train SB3's DDPG, TD3 or SAC; returns its deterministic policy, obs → env action."""
    import gymnasium
    from stable_baselines3 import DDPG, SAC, TD3
    from stable_baselines3.common.noise import NormalActionNoise

    env = gymnasium.make(task)
    common = dict(
        learning_rate=budget.learning_rate,
        buffer_size=budget.buffer_size,
        learning_starts=budget.warmup_steps,
        batch_size=budget.batch_size,
        tau=budget.tau,
        gamma=budget.gamma,
        train_freq=1,
        gradient_steps=1,
        policy_kwargs={"net_arch": list(budget.hidden)},
        seed=seed,
        device="cpu",
        verbose=0,
    )
    if learner in ("sb3-ddpg", "sb3-td3"):
        n = int(np.prod(env.action_space.shape))
        noise = NormalActionNoise(np.zeros(n), budget.noise_std * np.ones(n))
        algo = DDPG if learner == "sb3-ddpg" else TD3
        model: Any = algo("MlpPolicy", env, action_noise=noise, **common)
    else:
        model = SAC("MlpPolicy", env, **common)
    model.learn(total_timesteps=budget.steps)
    env.close()
    return lambda obs: model.predict(obs, deterministic=True)[0]


def run_one(task: str, learner: str, seed: int, budget: Budget) -> dict[str, Any]:
    """Train ``learner`` on ``task`` with ``seed`` for the ``budget``, then score it: one
    row of :data:`COLUMNS`."""
    import gymnasium

    configure_torch(1)
    train = train_ours if learner.startswith("ours-") else train_sb3
    policy = train(task, learner, seed, budget)
    env = gymnasium.make(task)
    returns = evaluate(env, policy, budget.eval_episodes)
    env.close()
    return {
        "task": task,
        "learner": learner,
        "seed": seed,
        "steps": budget.steps,
        "warmup_steps": budget.warmup_steps,
        "eval_episodes": budget.eval_episodes,
        "mean_return": float(returns.mean()),
        "std_return": float(returns.std()),
        "min_return": float(returns.min()),
        "max_return": float(returns.max()),
    }


def t_interval(values: np.ndarray, level: float = 0.95) -> tuple[float, float, float]:
    """Mean and the two-sided Student-t interval of the mean across ``values`` (n,); for
    n = 1 the interval is the value itself."""
    from scipy import stats

    values = np.asarray(values, dtype=np.float64)
    mean = float(values.mean())
    if len(values) < 2:
        return mean, mean, mean
    half = float(stats.t.ppf(0.5 + level / 2, len(values) - 1) * stats.sem(values))
    return mean, mean - half, mean + half


def summary(rows: pd.DataFrame) -> pd.DataFrame:
    """Per task and learner: seeds, mean of the runs' scores and its 95 % t-interval across
    seeds; for ours, ``verdict`` against :data:`REFERENCE`'s interval on the task: ``within``,
    ``better`` (above it) or ``below``."""
    out = []
    for (task, learner), group in rows.groupby(["task", "learner"], sort=False):
        mean, low, high = t_interval(group["mean_return"].to_numpy())
        out.append(
            {
                "task": task,
                "learner": learner,
                "seeds": len(group),
                "mean": mean,
                "ci_low": low,
                "ci_high": high,
            }
        )
    table = pd.DataFrame(out)
    verdicts = []
    for row in table.itertuples():
        reference = table[(table.task == row.task) & (table.learner == REFERENCE)]
        if not row.learner.startswith("ours-") or reference.empty:
            verdicts.append("")
            continue
        low, high = float(reference.ci_low.iloc[0]), float(reference.ci_high.iloc[0])
        verdicts.append("below" if row.mean < low else "better" if row.mean > high else "within")
    table["verdict"] = verdicts
    return table


def _provenance(argv: list[str]) -> str:
    import gymnasium
    import stable_baselines3
    import torch

    command = " ".join(["python -m benchmarks.learners", *recorded_argv(argv)])
    versions = (
        f"stable-baselines3 {stable_baselines3.__version__}; gymnasium {gymnasium.__version__}; "
        f"torch {torch.__version__}, one thread"
    )
    return provenance_line(command, versions)


def _names(text: str, option: str, known: tuple[str, ...]) -> list[str]:
    names = [name.strip() for name in text.split(",") if name.strip()]
    unknown = [name for name in names if name not in known]
    if not names or unknown:
        raise ConfigError(f"{option} must be some of {', '.join(known)}, got {text!r}")
    return names


def _seeds(text: str) -> list[int]:
    parts = [part.strip() for part in text.split(",")]
    if not all(part.isdigit() and int(part) < EVAL_SEED for part in parts):
        raise ConfigError(
            f"--seeds must be integers 0…{EVAL_SEED - 1} separated by commas "
            f"(evaluation uses {EVAL_SEED} on), got {text!r}"
        )
    return [int(part) for part in parts]


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    doc = (__doc__ or "").splitlines()[0]
    parser = argparse.ArgumentParser(prog="python -m benchmarks.learners", description=doc)
    parser.add_argument("--out", type=Path, default=Path("docs/learner-check.csv"))
    parser.add_argument("--tasks", default=",".join(BUDGETS))
    parser.add_argument("--seeds", default="0,1,2")
    parser.add_argument("--learners", default=",".join(LEARNERS))
    parser.add_argument("--force", action="store_true", help="overwrite an existing --out file")
    args = parser.parse_args(argv)
    try:
        tasks = _names(args.tasks, "--tasks", tuple(BUDGETS))
        learners = _names(args.learners, "--learners", LEARNERS)
        seeds = _seeds(args.seeds)
        refuse_existing_files("--out", (args.out,), args.force)
    except ConfigError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    rows = []
    start = time.perf_counter()
    for task in tasks:
        for seed in seeds:
            for learner in learners:  # interleaved, so a slower machine phase hits all alike
                began, cpu = time.perf_counter(), time.process_time()
                rows.append(run_one(task, learner, seed, BUDGETS[task]))
                print(
                    f"{task} {learner} seed {seed}: {rows[-1]['mean_return']:.1f} "
                    f"({time.perf_counter() - began:.0f} s, cpu {time.process_time() - cpu:.0f} s)",
                    flush=True,
                )
    frame = pd.DataFrame(rows, columns=COLUMNS)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    write_csv(args.out, frame, _provenance(argv))
    table = summary(frame)
    with pd.option_context("display.width", 160):
        print(table.to_string(index=False, float_format=lambda v: f"{v:.1f}"))
    budgets = "; ".join(f"{task}: {asdict(BUDGETS[task])}" for task in tasks)
    print(f"budgets: {budgets}")
    print(
        f"wall time: {(time.perf_counter() - start) / 60:.1f} min, "
        f"cpu {time.process_time() / 60:.1f} min"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
