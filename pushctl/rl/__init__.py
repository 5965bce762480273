"""Residual reinforcement learning: the gymnasium environment, DDPG, and the training loop.

Importing this package registers the environment as ``pushctl/Push-v0``::

    import gymnasium, pushctl.rl
    env = gymnasium.make("pushctl/Push-v0")
    envs = gymnasium.make_vec("pushctl/Push-v0", num_envs=8)  # pushctl.rl.vector_env
"""

import gymnasium

ENV_ID = "pushctl/Push-v0"

if ENV_ID not in gymnasium.registry:
    gymnasium.register(
        id=ENV_ID,
        entry_point="pushctl.rl.env:PushEnv",
        vector_entry_point="pushctl.rl.vector_env:make_push_vector_env",
    )
