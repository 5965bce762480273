"""Compiling the numba kernels once, before a run starts the processes that use them.

numba compiles pushctl's kernels (the world step, the MLCP's pivoting, the PD law, the
friction field, the batched actor) at their first call and keeps them in its disk cache
(``cache=True``), so a process finds them there afterwards. A fresh clone has no cache: the
first push in it takes about 50 s of one core. ``pushctl train --seeds 0,1,2`` starts its
seeds' processes at once (on this 2-core machine three, one per seed; one seed alone runs
its learner and two collectors), and each would compile the same kernels: 150 s of core
time, 75 s on the two cores before any seed trains. :func:`compile_kernels` runs the code paths of a
training run once, in the calling process, before those processes start (50 s, then each
loads the kernels from the cache); with the cache already filled it takes about a second.
"""

from __future__ import annotations

from dataclasses import replace

import torch

from pushctl.control.gains import PDGains
from pushctl.rl.collect import Behaviour, EpisodeRecord, collect_episodes, portable
from pushctl.rl.networks import Actor, ActorPolicy, initialise
from pushctl.task.env import PushEnv
from pushctl.task.env_config import EnvConfig
from pushctl.task.vector_env import PushVectorEnv

WARM_UP_DURATION = 1.0
"""Seconds pushed [s]: long enough for the gate to open and a prong to slip (the cold MLCP
path and its pivoting), short enough to cost a second once compiled."""


def compile_kernels(
    env_config: EnvConfig, gains: PDGains, hidden: tuple[int, ...]
) -> EpisodeRecord:
    """Push one short episode of ``env_config``'s first object and profile with an actor of
    ``hidden`` layers whose large random actions make the prongs slip, and PD-only on the
    same scenario (the training curves' and the validation's push): every kernel a
    training run calls is then in numba's cache. Returns the episode's record (its
    ``pd`` the PD-only push's errors). It draws from generators of its own, never a global
    one: no result of a run depends on it."""
    config = replace(env_config, duration=WARM_UP_DURATION, gate_threshold=0.0)
    vector = PushVectorEnv.of([PushEnv(config, gains)])
    shape = vector.single_observation_space.shape
    assert shape is not None  # a Box
    actor = Actor(shape[0], 3, hidden)
    initialise(actor, torch.Generator().manual_seed(0), final_bound=1.0)
    behaviour = Behaviour(
        warmup=False,
        actor_state=portable(ActorPolicy(actor.eval()).state()),
        ou_theta=0.15,
        ou_sigma=0.2,
        ou_dt=1.0,
    )
    return collect_episodes(vector, 0, [0], behaviour, pd_only=[0])[0]
