"""The env's reward (``ballenv.envs.batch``): the documented tolerance of the predicted apex, bounded,
and never a gain from ending an episode early."""

import math

import gymnasium as gym
import numpy as np
import pytest

import ballenv  # noqa: F401  (registers the env)
from ballenv.controllers import PressurePump
from ballenv.envs.batch import REWARD_AT_MARGIN, height_reward

MODES = ("pressure", "paddle")


def test_height_reward_is_deepmind_controls_gaussian_tolerance():
    assert height_reward(0.0, 0.5) == 1.0
    assert height_reward(0.5, 0.5) == pytest.approx(REWARD_AT_MARGIN, rel=1e-12)
    assert height_reward(0.25, 0.5) == pytest.approx(REWARD_AT_MARGIN**0.25, rel=1e-12)
    errors = np.linspace(0.0, 3.0, 31)
    values = [height_reward(e, 0.5) for e in errors]
    assert all(0.0 < v <= 1.0 for v in values)
    assert np.all(np.diff(values) < 0.0)


@pytest.mark.parametrize("mode", MODES)
def test_reward_is_in_zero_one_and_is_the_sum_of_its_terms(mode):
    env = gym.make("InflatedBall-v1", action_mode=mode)
    env.reset(seed=4)
    env.action_space.seed(4)
    rewards = []
    for _ in range(400):
        _, reward, terminated, truncated, info = env.step(env.action_space.sample())
        terms = [v for k, v in info.items() if k.startswith("reward_")]
        assert reward == pytest.approx(sum(terms), abs=1e-15)
        rewards.append(reward)
        if terminated or truncated:
            env.reset()
    rewards = np.array(rewards)
    assert np.all((rewards >= 0.0) & (rewards <= 1.0))
    assert rewards.max() > 0.5 and rewards.min() < 0.5  # random actions do reach and miss the target


def test_reward_in_flight_is_the_tolerance_of_the_ballistic_apex():
    env = gym.make("InflatedBall-v1")
    obs, info = env.reset(seed=2)
    structure = env.unwrapped.observation_structure
    target = info["target_height"]
    margin = env.unwrapped.config.reward_margin
    g = env.unwrapped.config.gravity
    for _ in range(5):  # the ball falls from rest: in flight, no contact yet
        obs, reward, *_ = env.step(np.array([0.0], dtype=np.float32))
        y = float(obs[structure["centre_of_mass_position"]][1])
        vy = float(obs[structure["centre_of_mass_velocity"]][1])
        assert not obs[structure["ground_normal_force"]].any()
        apex = y + 0.5 * vy * vy / g  # = the drop height while it falls freely
        expected = math.exp(-0.5 * (math.sqrt(2 * math.log(10)) * abs(apex - target) / target / margin) ** 2)
        assert reward == pytest.approx(expected, rel=1e-5)  # the observation is float32


@pytest.mark.parametrize("seed", [0, 1])
def test_ending_early_never_pays(seed):
    """The pump keeps the ball bouncing; a quitter pumps alike for 150 steps, then lets the gas out
    until the ball rests (terminated early): its return is lower."""

    def episode(quit_at):
        env = gym.make("InflatedBall-v1")
        obs, _ = env.reset(seed=seed)
        pump = PressurePump(env.unwrapped.observation_structure)
        total, steps = 0.0, 0
        while True:
            action = pump.act(obs) if steps < quit_at else np.array([-1.0], dtype=np.float32)
            obs, reward, terminated, truncated, _ = env.step(action)
            total += reward
            steps += 1
            if terminated or truncated:
                return total, steps, terminated

    kept, kept_steps, _ = episode(quit_at=10**9)
    quit, quit_steps, quit_terminated = episode(quit_at=150)
    assert quit_terminated and quit_steps < kept_steps
    assert quit < kept
