"""The env's reward (``ballenv.envs.batch``): the documented tolerance of the predicted apex, bounded,
and never a gain from ending an episode early."""

import math

import gymnasium as gym
import numpy as np
import pytest

import ballenv  # noqa: F401  (registers the env)
from ballenv.controllers import PaddleDribble, PressurePump
from ballenv.envs.batch import ENVS_PER_LINE, REWARD_AT_MARGIN, guided_chunks, height_reward
from ballenv.physics.ring import total_mass

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


def _tolerance(height, target, margin):
    return math.exp(-0.5 * (math.sqrt(2 * math.log(10)) * abs(height - target) / target / margin) ** 2)


def test_reward_measures_the_ballistic_apex_rising_and_the_last_apex_falling():
    """Falling from rest, the reward is that of the start height (the ball's last apex, observed as
    ``last_apex``); rising after its first bounce, that of its ballistic apex ``y + vy^2 / 2g``;
    after that flight's apex, that of the apex event the env reported."""
    env = gym.make("InflatedBall-v1")
    obs, info = env.reset(seed=2)
    s = env.unwrapped.observation_structure
    target, margin = info["target_height"], env.unwrapped.config.reward_margin
    g = env.unwrapped.config.gravity
    start = float(obs[s["centre_of_mass_position"]][1])
    assert obs[s["last_apex"]][0] == pytest.approx(start, rel=1e-6)
    phases = {"falling": 0, "rising": 0, "after apex": 0}
    apex = None
    for _ in range(200):
        obs, reward, _, _, info = env.step(np.array([0.0], dtype=np.float32))
        y = float(obs[s["centre_of_mass_position"]][1])
        vy = float(obs[s["centre_of_mass_velocity"]][1])
        flying = not obs[s["ground_normal_force"]].any()
        if info["apex_count"]:
            apex = info["apex_height"]
            assert obs[s["last_apex"]][0] == pytest.approx(apex, rel=1e-6)
        if flying and apex is None and vy < 0.0 and phases["rising"] == 0:
            phases["falling"] += 1
            assert reward == pytest.approx(_tolerance(start, target, margin), rel=1e-5)
        elif flying and vy > 0.0:
            phases["rising"] += 1
            assert reward == pytest.approx(_tolerance(y + 0.5 * vy * vy / g, target, margin), rel=1e-4)
        elif flying and apex is not None:
            phases["after apex"] += 1
            assert reward == pytest.approx(_tolerance(apex, target, margin), rel=1e-5)
            break
    assert min(phases.values()) > 0, phases


def test_reward_favours_the_paddle_strike_that_hits_the_target():
    """The dribbler's strike sized for the bounce's true loss (retention 0.7 of the energy) hits the
    target far better than one that ignores the loss (retention 1); the reward ranks them alike."""
    scores = {}
    for retention in (0.7, 1.0):
        env = gym.make("InflatedBallPaddle-v1")
        config = env.unwrapped.config
        dribble = PaddleDribble(
            env.unwrapped.observation_structure, total_mass(config.ring(config.initial_pressure)),
            retention=retention,
        )  # fmt: skip
        total, errors = 0.0, []
        for seed in range(2):
            obs, _ = env.reset(seed=100 + seed)
            dribble.reset()
            while True:
                obs, reward, terminated, truncated, info = env.step(dribble.act(obs))
                total += reward
                if info["apex_count"]:
                    errors.append(abs(info["apex_height"] - info["target_height"]) / info["target_height"])
                if terminated or truncated:
                    break
        scores[retention] = (np.mean(errors), total)
    assert scores[0.7][0] < 0.5 * scores[1.0][0]
    assert scores[0.7][1] > scores[1.0][1]


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


@pytest.mark.parametrize("n_envs", [1, 2, 9, 64, 257])
@pytest.mark.parametrize("threads", [2, 3])
def test_guided_chunks_cover_every_env_once_shrinking_and_line_aligned(n_envs, threads):
    bounds = guided_chunks(n_envs, threads)
    sizes = np.diff(bounds)
    assert bounds[0] == 0 and bounds[-1] == n_envs and (sizes >= 1).all()
    assert (np.diff(sizes) <= 0).all()  # largest first, single envs last
    big = sizes >= ENVS_PER_LINE
    assert (sizes[big] % ENVS_PER_LINE == 0).all()
    assert (np.asarray(bounds[:-1])[big] % ENVS_PER_LINE == 0).all()  # big chunks start on a line
    if n_envs >= 2 * threads:
        assert sizes[-1] == 1
