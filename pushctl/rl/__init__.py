"""Learners of the residual: DDPG/TD3 (:mod:`pushctl.rl.ddpg`), stable-baselines3's SAC
(:mod:`pushctl.rl.sb3`), the replay buffer, exploration noise, networks, the training loop,
its collectors and its validation. The task they learn lives in :mod:`pushctl.task`."""
