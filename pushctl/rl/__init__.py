"""Residual reinforcement learning: the gymnasium environment, DDPG, and the training loop.

Importing this package registers the environment as ``pushctl/Push-v0``::

    import gymnasium, pushctl.rl
    env = gymnasium.make("pushctl/Push-v0")
"""

import gymnasium

ENV_ID = "pushctl/Push-v0"

if ENV_ID not in gymnasium.registry:
    gymnasium.register(id=ENV_ID, entry_point="pushctl.rl.env:PushEnv")
