"""Gymnasium environments: InflatedBall-v3 (single) and its native vector env, and the 3-D ball's
InflatedBall3D-v0 (ball3d/), registered once per action mode (one id per mode, as the RL Baselines3
Zoo keys its hyperparameters)."""

from gymnasium.envs.registration import register, registry

ENV_ID = "InflatedBall-v3"
PADDLE_ENV_ID = "InflatedBallPaddle-v3"  # InflatedBall-v3 with action_mode="paddle"
ENV_IDS = {"pressure": ENV_ID, "paddle": PADDLE_ENV_ID}  # action mode -> its env id
BALL3D_ENV_IDS = {"pressure": "InflatedBall3D-v0", "paddle": "InflatedBall3DPaddle-v0"}  # the 3-D ball's
MAX_EPISODE_STEPS = 1000


def register_envs() -> None:
    """Register the ids of ``ENV_IDS`` (repeatable: a second call changes nothing). Each sets its
    action mode through the spec's ``kwargs``; a keyword passed to ``gym.make`` overrides it."""
    for mode, env_id in ENV_IDS.items():
        if env_id in registry:
            continue
        register(
            id=env_id,
            entry_point="ballenv.envs.inflated_ball:InflatedBallEnv",
            vector_entry_point="ballenv.envs.vector:InflatedBallVectorEnv",
            max_episode_steps=MAX_EPISODE_STEPS,
            kwargs={"action_mode": mode},
        )
    for mode, env_id in BALL3D_ENV_IDS.items():
        if env_id not in registry:
            register(
                id=env_id,
                entry_point="ballenv.envs.ball3d.env:InflatedBall3DEnv",
                vector_entry_point="ballenv.envs.ball3d.vector:Ball3DVectorEnv",
                max_episode_steps=MAX_EPISODE_STEPS,
                kwargs={"action_mode": mode},
            )
