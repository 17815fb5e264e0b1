"""Gymnasium environments: InflatedBall-v1 (single) and its native vector env."""

from gymnasium.envs.registration import register, registry

ENV_ID = "InflatedBall-v1"
MAX_EPISODE_STEPS = 1000


def register_envs():
    """Register InflatedBall-v1 (repeatable: a second call changes nothing)."""
    if ENV_ID in registry:
        return
    register(
        id=ENV_ID,
        entry_point="ballenv.envs.inflated_ball:InflatedBallEnv",
        vector_entry_point="ballenv.envs.vector:InflatedBallVectorEnv",
        max_episode_steps=MAX_EPISODE_STEPS,
    )
