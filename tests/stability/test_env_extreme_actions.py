"""Stability suite: the largest actions of both action modes every step for 10,000 env steps (100 s of
simulated time at 100 Hz, through about ten resets): observations finite and inside the observation
space, rewards finite, the ball never below the ground by more than 1e-6 m, and no simulator
failure. The default run uses the env's own settings (the fast preset: generalized-alpha,
mass-modification); the other contact-method and integrator pairs run in ``make test-slow``."""

from dataclasses import replace

import numpy as np
import pytest

from ballenv.envs.batch import BallBatch
from ballenv.envs.inflated_ball import InflatedBallEnv

from .cases import CONTACTS, INTEGRATORS
from .invariants import GROUND_TOLERANCE

MODES = ("pressure", "paddle")
PATTERNS = ("plus", "minus", "alternating")


def _env(mode, contact=None, integrator=None):
    env = InflatedBallEnv(action_mode=mode)
    if contact is not None:
        scene = replace(env._batch.scene, contact=contact, integrator=integrator)
        env._batch = BallBatch(scene, 1, env.config.task_settings(), *env.config.observation_bounds())
    return env


def _run_extremes(env, pattern, steps=10_000):
    space = env.observation_space
    obs, _ = env.reset(seed=11)
    ends = {}
    deepest = 0.0
    episode = 0
    for k in range(steps):
        episode += 1
        value = {"plus": 1.0, "minus": -1.0, "alternating": 1.0 if k % 2 else -1.0}[pattern]
        obs, reward, terminated, truncated, info = env.step(np.array([value], dtype=np.float32))
        assert np.all(np.isfinite(obs)) and space.contains(obs), (k, info)
        assert np.isfinite(reward)
        x = env._batch.state.x[0]
        assert np.all(np.isfinite(x)) and np.all(np.isfinite(env._batch.state.v[0]))
        deepest = max(deepest, -float(x[:, 1].min()))
        if terminated or truncated or episode == 1000:  # the registered env's time limit
            reason = info["termination"] or "time_limit"
            ends[reason] = ends.get(reason, 0) + 1
            obs, _ = env.reset()
            episode = 0
    assert "sim_failure" not in ends, ends
    assert deepest <= GROUND_TOLERANCE
    return ends


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("pattern", PATTERNS)
def test_extreme_actions_for_10000_steps_stay_finite_in_bounds_and_above_ground(mode, pattern):
    ends = _run_extremes(_env(mode), pattern)
    assert sum(ends.values()) >= 10


@pytest.mark.slow
@pytest.mark.parametrize("integrator", INTEGRATORS)
@pytest.mark.parametrize("contact", CONTACTS)
@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("pattern", ("plus", "alternating"))
def test_extreme_actions_with_every_contact_method_and_integrator(pattern, mode, contact, integrator):
    _run_extremes(_env(mode, contact, integrator), pattern)
