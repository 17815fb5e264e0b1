"""The 3-D ball's native vector env: the numbers of single envs to the bit, on one thread or two,
autoreset as Gymnasium's NEXT_STEP mode, clear errors."""

import gymnasium as gym
import numpy as np
import pytest

import ballenv  # noqa: F401  (registers the envs)
from ballenv.envs.ball3d.vector import Ball3DVectorEnv

ID = "InflatedBall3DPaddle-v0"
STEPS = 14  # with episodes of 6 steps: two autoresets


def _actions(n_envs, rng):
    return [rng.uniform(-1.0, 1.0, (n_envs, 3)) for _ in range(STEPS)]


def _singles(actions, n_envs, seed):
    """What single envs of seeds seed + i give under NEXT_STEP autoreset."""
    envs = [gym.make(ID, max_episode_steps=6) for _ in range(n_envs)]
    obs = [env.reset(seed=seed + i)[0] for i, env in enumerate(envs)]
    done = [False] * n_envs
    rows = []
    for a in actions:
        out = []
        for i, env in enumerate(envs):
            if done[i]:
                o, _ = env.reset()
                out.append((o, 0.0, False, False))
                done[i] = False
                continue
            o, r, term, trunc, _ = env.step(a[i])
            done[i] = term or trunc
            out.append((o, r, term, trunc))
        rows.append(out)
    return obs, rows


@pytest.mark.parametrize("threads", [1, 2])
def test_the_vector_env_gives_the_single_envs_numbers_to_the_bit(threads):
    actions = _actions(3, np.random.default_rng(1))
    obs0, rows = _singles(actions, 3, seed=20)
    vec = gym.make_vec(ID, num_envs=3, max_episode_steps=6, num_threads=threads)
    assert isinstance(vec.unwrapped, Ball3DVectorEnv)
    obs, _ = vec.reset(seed=20)
    assert np.array_equal(obs, np.stack(obs0))
    for a, row in zip(actions, rows, strict=True):
        obs, reward, term, trunc, info = vec.step(a)
        assert np.array_equal(obs, np.stack([r[0] for r in row]))
        assert np.array_equal(reward, [r[1] for r in row])
        assert np.array_equal(term, [r[2] for r in row]) and np.array_equal(trunc, [r[3] for r in row])
    assert set(info) >= {"reward_height", "reward_spot", "termination", "target_spot"}
    vec.close()


def test_bad_options_are_clear_errors():
    with pytest.raises(ValueError, match="num_envs"):
        Ball3DVectorEnv(num_envs=0)
    with pytest.raises(ValueError, match="num_threads"):
        Ball3DVectorEnv(num_envs=2, num_threads=0)
    vec = Ball3DVectorEnv(num_envs=2, action_mode="paddle")
    vec.reset(seed=0)
    with pytest.raises(ValueError, match="vector step actions"):
        vec.step(np.zeros((3, 3)))
