"""The native vector env against single envs, and Gymnasium's own vectorisations."""

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.error import ResetNeeded

import ballenv  # noqa: F401  (registers the env)
from ballenv.envs.vector import InflatedBallVectorEnv


def _single_rollouts(n_envs, seed, actions, env_id="InflatedBall-v3", **kwargs):
    """Step n single envs as Gymnasium's NEXT_STEP autoreset does: the step after an episode ends
    resets that env and returns reward 0."""
    envs = [gym.make(env_id, **kwargs) for _ in range(n_envs)]
    obs = [np.stack([e.reset(seed=seed + i)[0] for i, e in enumerate(envs)])]
    rewards, terms, truncs = [], [], []
    done = np.zeros(n_envs, dtype=bool)
    for a in actions:
        step = []
        for i, e in enumerate(envs):
            if done[i]:
                step.append((e.reset()[0], 0.0, False, False))
            else:
                o, r, te, tr, _ = e.step(a[i])
                step.append((o, r, te, tr))
        obs.append(np.stack([s[0] for s in step]))
        rewards.append([s[1] for s in step])
        terms.append([s[2] for s in step])
        truncs.append([s[3] for s in step])
        done = np.array(terms[-1]) | np.array(truncs[-1])
    return np.array(obs), np.array(rewards), np.array(terms), np.array(truncs)


def _vector_rollouts(venv, seed, actions):
    obs = [venv.reset(seed=seed)[0]]
    rewards, terms, truncs = [], [], []
    for a in actions:
        o, r, te, tr, _ = venv.step(a)
        obs.append(o)
        rewards.append(r)
        terms.append(te)
        truncs.append(tr)
    return np.array(obs), np.array(rewards), np.array(terms), np.array(truncs)


def _actions(n_steps, n_envs, seed=0):
    return np.random.default_rng(seed).uniform(-1, 1, (n_steps, n_envs, 1)).astype(np.float32)


@pytest.mark.parametrize("mode", ["pressure", "paddle"])
def test_native_vector_env_matches_single_envs_through_autoresets(mode):
    # a short time limit so that episodes end (truncation and termination) and autoreset
    n_envs, steps = 4, 400
    actions = _actions(steps, n_envs)
    venv = gym.make_vec(
        "InflatedBall-v3", num_envs=n_envs, vectorization_mode="vector_entry_point", action_mode=mode,
        max_episode_steps=150,
    )  # fmt: skip
    assert isinstance(venv.unwrapped, InflatedBallVectorEnv)
    vec = _vector_rollouts(venv, 5, actions)
    single = _single_rollouts(n_envs, 5, actions, action_mode=mode, max_episode_steps=150)
    np.testing.assert_allclose(vec[0], single[0], rtol=0, atol=1e-12)
    np.testing.assert_allclose(vec[1], single[1], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(vec[2], single[2])
    np.testing.assert_array_equal(vec[3], single[3])
    assert vec[3].sum() >= n_envs  # every env was truncated at least once


@pytest.mark.parametrize("mode", ["pressure", "paddle"])
def test_threads_match_one_thread_bit_for_bit(mode):
    # 9 envs on 2 threads: chunks of unequal size, taken by whichever thread is free; autoresets
    n_envs, steps = 9, 160
    actions = _actions(steps, n_envs, seed=3)
    runs = []
    for threads in (1, 2):
        venv = InflatedBallVectorEnv(
            num_envs=n_envs, num_threads=threads, action_mode=mode, max_episode_steps=70
        )
        assert venv._batch.threads == threads
        runs.append(_vector_rollouts(venv, 11, actions))
        venv.close()
    for one, two in zip(*runs, strict=True):
        np.testing.assert_array_equal(one, two)
    assert runs[0][3].sum() >= n_envs  # every env was truncated at least once


def test_sync_vector_env_matches_single_envs():
    actions = _actions(120, 2, seed=1)
    venv = gym.make_vec("InflatedBall-v3", num_envs=2, vectorization_mode="sync")
    vec = _vector_rollouts(venv, 9, actions)
    single = _single_rollouts(2, 9, actions)
    np.testing.assert_array_equal(vec[0], single[0])
    np.testing.assert_array_equal(vec[1], single[1])


def test_async_spawned_vector_env_matches_single_envs():
    actions = _actions(60, 2, seed=2)
    venv = gym.make_vec(
        "ballenv:InflatedBall-v3", num_envs=2, vectorization_mode="async", vector_kwargs={"context": "spawn"}
    )
    try:
        vec = _vector_rollouts(venv, 4, actions)
    finally:
        venv.close()
    single = _single_rollouts(2, 4, actions)
    np.testing.assert_array_equal(vec[0], single[0])
    np.testing.assert_array_equal(vec[1], single[1])


def test_vector_env_spaces_and_errors():
    venv = InflatedBallVectorEnv(num_envs=3)
    obs, info = venv.reset(seed=0)
    assert venv.observation_space.contains(obs)
    assert info["target_height"].shape == (3,)
    with pytest.raises(ValueError, match="actions"):
        venv.step(np.zeros((2, 1), dtype=np.float32))
    with pytest.raises(ValueError, match="num_envs"):
        InflatedBallVectorEnv(num_envs=0)
    with pytest.raises(ValueError, match=r"num_threads = 0 .* \[1, "):
        InflatedBallVectorEnv(num_envs=2, num_threads=0)
    frames = InflatedBallVectorEnv(num_envs=2, render_mode="rgb_array")
    frames.reset(seed=0)
    images = frames.render()
    assert len(images) == 2 and images[0].dtype == np.uint8


def test_vector_reset_takes_one_seed_per_env():
    venv = InflatedBallVectorEnv(num_envs=2)
    obs, info = venv.reset(seed=[7, 5])
    for i, seed in enumerate((7, 5)):
        single_obs, single_info = gym.make("InflatedBall-v3").reset(seed=seed)
        np.testing.assert_array_equal(obs[i], single_obs)
        assert info["target_height"][i] == single_info["target_height"]
    with pytest.raises(ValueError, match="seed has 3 entries: must have num_envs = 2"):
        venv.reset(seed=[1, 2, 3])


def test_vector_step_or_render_before_reset_asks_for_a_reset():
    venv = InflatedBallVectorEnv(num_envs=2, num_threads=1, render_mode="rgb_array")
    with pytest.raises(ResetNeeded, match=r"vector step\(\) was called before reset\(\)"):
        venv.step(np.zeros((2, 1), dtype=np.float32))
    with pytest.raises(ResetNeeded, match=r"vector render\(\) was called before reset\(\)"):
        venv.render()
    venv.reset(seed=0)
    obs, reward, *_ = venv.step(np.zeros((2, 1), dtype=np.float32))
    assert np.all(np.isfinite(obs)) and np.all((reward >= 0.0) & (reward <= 1.0))
    venv.close()


def test_wrappers_and_vector_kwargs_go_to_sync_vectorisation_and_are_refused_by_the_native_env():
    from gymnasium.error import Error
    from gymnasium.vector import AutoresetMode, SyncVectorEnv
    from gymnasium.wrappers import TransformReward

    def halved(env):
        return TransformReward(env, lambda r: 0.5 * r)

    actions = _actions(40, 2, seed=4)
    venv = gym.make_vec(
        "InflatedBall-v3", num_envs=2, vectorization_mode="sync", wrappers=[halved],
        vector_kwargs={"autoreset_mode": AutoresetMode.SAME_STEP},
    )  # fmt: skip
    assert isinstance(venv, SyncVectorEnv) and venv.metadata["autoreset_mode"] == AutoresetMode.SAME_STEP
    assert all(isinstance(e, TransformReward) for e in venv.envs)
    wrapped = _vector_rollouts(venv, 9, actions)
    plain = _vector_rollouts(gym.make_vec("InflatedBall-v3", num_envs=2), 9, actions)  # native
    np.testing.assert_allclose(wrapped[0], plain[0], rtol=0, atol=1e-12)
    np.testing.assert_allclose(wrapped[1], 0.5 * plain[1], rtol=1e-12)
    # the default (native) mode: Gymnasium refuses both before the env is built
    with pytest.raises(Error, match="wrappers argument"):
        gym.make_vec("InflatedBall-v3", num_envs=2, wrappers=[halved])
    with pytest.raises(Error, match="`vector_kwargs` is not empty"):
        gym.make_vec("InflatedBall-v3", num_envs=2, vector_kwargs={"copy": False})
    # and so does the native env's constructor, naming the mode that takes them
    for name in ("wrappers", "vector_kwargs"):
        with pytest.raises(TypeError, match=f"takes no '{name}': .*vectorization_mode=\"sync\""):
            InflatedBallVectorEnv(num_envs=2, **{name: []})


def test_the_native_vector_env_options_are_documented_in_its_module():
    import inspect

    import ballenv.envs.vector as vector
    from ballenv.envs.inflated_ball import InflatedBallEnv

    documented = InflatedBallVectorEnv.__doc__  # the API reference's (docs/api/envs.md)
    assert "InflatedBallVectorEnv" in vector.__doc__
    for name in inspect.signature(InflatedBallVectorEnv.__init__).parameters:
        if name not in ("self", "kwargs"):
            assert f"| {name} |" in documented, name
    assert 'vectorization_mode="sync"' in documented
    assert "## Vector Environments" in InflatedBallEnv.__doc__
    assert 'vectorization_mode="sync"' in InflatedBallEnv.__doc__
