"""Stability suite of the 3-D envs: the largest actions every step for 2,000 env steps per mode and
pattern (20 s of simulated time, through resets): observations finite and inside the observation
space, rewards in [0, 1], no vertex below the ground by more than 1e-6 m, and no simulator failure."""

import numpy as np
import pytest

from ballenv.envs.ball3d.env import InflatedBall3DEnv

PATTERNS = ("plus", "minus", "alternating")
STEPS = 2000


def _action(mode, pattern, k):
    value = {"plus": 1.0, "minus": -1.0, "alternating": 1.0 if k % 2 else -1.0}[pattern]
    if mode == "pressure":
        return np.array([value])
    return np.array([value, value, -value])  # the strongest strike at the widest tilt


@pytest.mark.slow
@pytest.mark.parametrize("mode", ("pressure", "paddle"))
@pytest.mark.parametrize("pattern", PATTERNS)
def test_extreme_actions_keep_the_3d_ball_valid(mode, pattern):
    env = InflatedBall3DEnv(action_mode=mode)
    env.reset(seed=11)
    for k in range(STEPS):
        obs, reward, terminated, truncated, info = env.step(_action(mode, pattern, k))
        assert np.all(np.isfinite(obs)) and env.observation_space.contains(obs), (k, info)
        assert 0.0 <= reward <= 1.0
        assert not info["sim_failure"], info["sim_failure_reason"]
        assert env.ball.sim.x[0][:, 2].min() > -1e-6, k
        if terminated or truncated or env.ball.steps >= 1000:  # 1000: the ids' time limit
            env.reset()
