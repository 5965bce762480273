"""The push task: the gymnasium environment a controller or a learner pushes in (single and
vector), its configuration, observation and action spaces, draws and registered versions.

Importing this package (``import pushctl`` does, once gymnasium is imported) registers the
environment's versions; the newest is :data:`ENV_ID`::

    import gymnasium, pushctl
    env = gymnasium.make("pushctl/Push-v1")
    envs = gymnasium.make_vec("pushctl/Push-v1", num_envs=8)  # pushctl.task.vector_env

Both ids build :class:`~pushctl.task.env.PushEnv`; an id fixes the settings a ``config``
left out defaults to (:mod:`pushctl.task.versions`). A policy file keeps the settings it was
trained with, so it runs on the version it was trained on whatever the defaults are now.

Version history
    - v1: the residual is added to the feedback law's action (``base_law = "feedback"``)
      and acts at every step, inside the gate's dead band too (``policy_gated = False``);
      the observation gains the pose error's rate, the plan's speed and the law's own
      action (``observe_context``); a decision every 100 ms (``action_repeat = 10``); the
      reward's pose term is on (``w_pose = 20``).
    - v0: the residual on PD alone, switched by the gate, a decision every 10 ms, the
      reward of eq. 17 without the pose term (:class:`~pushctl.task.env_config.EnvConfig`'s
      defaults). Still registered: the shipped policies were trained on its observation.
"""

import gymnasium

ENV_ID = "pushctl/Push-v1"
"""The newest version of the push environment."""

VERSIONS = {
    "pushctl/Push-v0": ("push_v0", "push_v0_vector"),
    ENV_ID: ("push_v1", "push_v1_vector"),
}
"""Each registered id → its (single, vector) entry points in :mod:`pushctl.task.versions`."""

for _id, (_single, _vector) in VERSIONS.items():
    if _id not in gymnasium.registry:
        gymnasium.register(
            id=_id,
            entry_point=f"pushctl.task.versions:{_single}",
            vector_entry_point=f"pushctl.task.versions:{_vector}",
        )
