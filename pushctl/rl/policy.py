"""A trained residual policy on disk (``policy.pt``) and running it on one scenario.

The file holds the actor (weights, widths, observation scale), the environment settings it
was trained with (action scale, gate, the reward weights) and the provenance line of the run
that made it.
"""

from __future__ import annotations

import copy
import re
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from pushctl.control.gains import PDGains
from pushctl.episode.runner import Episode
from pushctl.episode.trace import Trace
from pushctl.errors import ConfigError, StateError, reason
from pushctl.files.provenance import one_line
from pushctl.rl.checkpoint import content_digest, load_checked, nonfinite_entry, save_checked
from pushctl.rl.networks import ActorPolicy
from pushctl.task.env import PushEnv
from pushctl.task.env_config import EnvConfig
from pushctl.task.feedback_actor import FeedbackActor

POLICY_FORMAT = 1


@dataclass(frozen=True)
class TrainedPolicy:
    """``actor``: the deterministic residual policy; ``env``: the settings it was trained
    with; ``made_by``: the training run's provenance line."""

    actor: ActorPolicy
    env: EnvConfig
    made_by: str

    @property
    def seed(self) -> int | None:
        """The training run's seed, read from its provenance line (None if it names none)."""
        found = re.search(r"seed (\d+) \(training stream\)", self.made_by)
        return int(found.group(1)) if found else None


def save_atomic(path: Path, state: dict[str, Any]) -> None:
    """``torch.save`` to a temporary file beside ``path``, then renamed over it, with the
    content's digest (:func:`pushctl.rl.checkpoint.save_checked`)."""
    save_checked(Path(path), state)


def write_policy(path: Path, actor_state: dict[str, Any], env: EnvConfig, made_by: str) -> None:
    """Save an actor (``DDPGAgent.actor_state()``) with its env settings, atomically."""
    state = {
        "format": POLICY_FORMAT,
        "actor": actor_state,
        "env": env.to_dict(),
        "made_by": made_by,
    }
    save_atomic(path, state)


def holds_actor(path: Path, actor_state: dict[str, Any], made_by: str) -> bool:
    """Whether the policy file ``path`` holds ``actor_state`` (``DDPGAgent.actor_state()``)
    under the provenance line ``made_by``: False if it is missing or damaged."""
    if not path.is_file():
        return False
    try:
        state = load_checked(path, "policy file")
    except ConfigError:
        return False
    same = content_digest(state.get("actor")) == content_digest(actor_state)
    return same and state.get("made_by") == made_by


def load_policy(path: str | Path, *, trust_undigested: bool = False) -> TrainedPolicy:
    """Read ``policy.pt``; ConfigError (one line) if it is missing, damaged (its checksums
    or digest: :mod:`pushctl.rl.checkpoint`; without one, unless ``trust_undigested``), not
    a policy, or holds non-finite weights."""
    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"no policy file at {path}: train one with `pushctl train`")
    state = load_checked(path, "policy file", trust_undigested=trust_undigested)
    try:
        if state.get("format") != POLICY_FORMAT:
            raise ValueError(f"format {state.get('format')!r}, this pushctl reads {POLICY_FORMAT}")
        bad = nonfinite_entry(state["actor"]["actor"])
        if bad is not None:
            raise ValueError(f"non-finite weights (NaN or infinity) in {bad}")
        return TrainedPolicy(
            actor=ActorPolicy.from_state(state["actor"]),
            env=EnvConfig.from_saved(state["env"]),
            made_by=str(state["made_by"]),
        )
    except ConfigError as exc:
        raise ConfigError(f"policy file {path}: {exc}") from None
    except KeyError as exc:
        raise ConfigError(f"policy file {path} is not a policy: {reason(exc)} entry") from None
    except Exception as exc:  # a state dict of other shapes: torch's many error types
        why = one_line(str(exc), 120) or type(exc).__name__
        raise ConfigError(f"policy file {path} is not a policy: {why}") from None


def evaluation_env(policy: TrainedPolicy, gains: PDGains, plant: str = "sim") -> PushEnv:
    """The policy's environment drawing from the evaluation stream with ``plant``'s ranges."""
    return PushEnv(replace(policy.env, stream="evaluation", plant=plant), gains)


def run_policy(env: PushEnv, actor: ActorPolicy, options: dict[str, Any]) -> Trace:
    """Reset ``env`` with ``options`` (see :data:`pushctl.task.env.RESET_OPTIONS`), push with
    the deterministic ``actor`` (no exploration), and return the trace."""
    env.reset(options=options)
    finish_with_policy(env, actor)
    assert env.episode is not None
    return env.episode.trace()


def pd_only_episode(env: PushEnv) -> Episode:
    """The PD-only comparison push of the scenario ``env`` was just reset to, ready to
    ``finish()``: a copy of its episode as the reset left it, so the same plan, plant
    effects (the proxy's latency, friction and noise generators), engine and approach. Its
    ``finish()`` is the trace of a fresh ``Episode(env.scenario, env.gains, plan=env.plan,
    effects=env.effects, engine=env.engine).run()``, without running the approach again.
    The one way the evaluation, the validation and the training curves build it. Where the
    reset re-landed the prongs (``landing = "measured"``), PD-only starts where the approach
    landed them (:attr:`PushEnv.believed_start`): it is open loop in the object's pose."""
    episode = env.episode
    if episode is None or episode.step_index != 0:
        raise StateError("the PD-only push is copied from an episode just reset, before a step")
    return copy.deepcopy(env.believed_start)


def finish_with_policy(env: PushEnv, actor: Callable[[np.ndarray], np.ndarray]) -> int:
    """Push the rest of ``env``'s episode with the deterministic ``actor`` (observation →
    action; a policy, or any controller of that form); return the number of steps its gate
    was open.

    The same push as step() after step() with the actor's actions, but the observation and
    the actor run only where the action can matter. With ``action_repeat`` = 1, only while
    the gate is open (the step ignores the action otherwise: :meth:`PushEnv.advance`). With
    ``action_repeat`` = k > 1 the actor decides at every k-th step, as step() does, and its
    action is held for the k steps (the gate may open within them). Without
    ``policy_gated`` the actor acts at every step the gate is shut too. With a ``base_law``
    the environment adds the law's action to it at every step (:meth:`PushEnv.advance`).
    """
    episode = env.episode
    if episode is None:
        raise StateError("call reset() before pushing with a policy")
    repeat, gated = env.config.action_repeat, env.config.policy_gated
    opened = 0
    held: np.ndarray | None = None
    decide = _decision(env, actor)
    while not episode.done:
        if repeat > 1 and episode.step_index % repeat == 0:
            held = decide()
        gate = env.gate_open
        opened += gate
        if gate or not gated:
            if repeat == 1:
                held = decide()
            env.advance(held)
        else:
            env.advance(None)
    return opened


def _decision(env: PushEnv, actor: Callable[[np.ndarray], np.ndarray]) -> Callable[[], np.ndarray]:
    """The actor's action on ``env``'s state now. The feedback law of ``env`` itself reads
    the state without the observation (:meth:`FeedbackActor.act`: the same floats); any
    other actor, a subclass of the law's included, gets the observation."""
    if type(actor) is FeedbackActor and actor.env is env:
        return lambda: np.array(actor.act())
    return lambda: actor(np.asarray(env.observation(), dtype=np.float64))
