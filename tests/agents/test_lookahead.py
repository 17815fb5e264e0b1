"""The pressure mode's privileged reference (``agents.lookahead``): its copies of the simulator are
exact, so the bounce it plans is the bounce the env then makes, and it pumps the ball to the target
far closer than the scripted pump."""

import gymnasium as gym
import numpy as np
import pytest

import ballenv  # noqa: F401  (registers the env)
from agents.baselines import make_policy
from agents.evaluate import run_episode
from agents.lookahead import LookaheadPaddle, LookaheadPump
from agents.policies import HeuristicPolicy

from ..benchmark_modules import load_benchmark


def test_the_planned_bounce_is_the_bounce_the_env_makes_to_the_bit():
    env = gym.make("InflatedBall-v3")
    policy = LookaheadPump(env, candidates=9)
    obs, _ = env.reset(seed=10_000)
    policy.reset(10_000)
    task = env.unwrapped._batch.task
    got, expected, planned, landed = [], [], np.nan, False
    for step in range(400):
        plans = step == 0 or task.apex_count[0] > 0  # at the start and after each apex
        action = policy.act(obs)
        if plans:
            planned, landed = policy.expected_error, False
        obs, _, _, _, info = env.step(action)
        landed |= not task.airborne[0]
        if info["apex_count"] and landed:
            got.append(abs(info["apex_height"] - info["target_height"]) / info["target_height"])
            expected.append(planned)
    assert len(got) >= 4
    np.testing.assert_array_equal(got, expected)


def test_lookahead_pumps_closer_to_the_target_than_the_scripted_pump():
    env = gym.make("InflatedBall-v3", max_episode_steps=500)
    errors = {
        policy.name: [np.mean(run_episode(env, policy, seed)[0]) for seed in (1, 2)]
        for policy in (LookaheadPump(env, candidates=21), HeuristicPolicy(env))
    }
    assert max(errors["lookahead"]) < 0.04 < min(errors["heuristic"]), errors


def test_the_planned_strike_sets_the_bounce_the_env_makes_to_the_bit():
    """The paddle's lookahead plans at the start and when the ball is in reach after a strike; the
    apex after the bounce it plans is the env's next apex after a landing."""
    env = gym.make("InflatedBall-v3", action_mode="paddle")
    policy = LookaheadPaddle(env, candidates=9)
    obs, _ = env.reset(seed=10_000)
    policy.reset(10_000)
    task = env.unwrapped._batch.task
    got, expected, planned, landed = [], [], [], False
    for _ in range(400):
        before = policy.expected_error, policy.candidate_errors
        action = policy.act(obs)
        if policy.candidate_errors is not before[1]:  # a new plan
            planned.append(policy.expected_error)
        if action[0] > -1.0:  # the strike: the next apex after a landing is its bounce's
            landed = False
            expected.append(planned[-1])
        obs, _, _, _, info = env.step(action)
        landed |= not task.airborne[0]
        if info["apex_count"] and landed and len(got) < len(expected):
            got.append(abs(info["apex_height"] - info["target_height"]) / info["target_height"])
    assert len(got) >= 4
    np.testing.assert_array_equal(got, expected[: len(got)])


def test_the_paddle_lookahead_strikes_closer_to_the_target_than_the_scripted_paddle():
    """Over the apexes after each episode's first (the start's drop, before any strike): measured
    0.010 against the scripted paddle's 0.019."""
    env = gym.make("InflatedBall-v3", action_mode="paddle", max_episode_steps=500)
    errors = {
        policy.name: np.mean(np.concatenate([run_episode(env, policy, seed)[0][1:] for seed in (1, 2)]))
        for policy in (LookaheadPaddle(env), HeuristicPolicy(env))
    }
    assert errors["lookahead"] < 0.75 * errors["heuristic"], errors


def test_the_paddle_lookahead_refuses_the_pressure_mode():
    with pytest.raises(ValueError, match="action_mode = 'pressure' is invalid: must be 'paddle'"):
        LookaheadPaddle(gym.make("InflatedBall-v3"))


def test_lookahead_refuses_the_paddle_mode_and_bad_candidates():
    with pytest.raises(ValueError, match="action_mode = 'paddle' is invalid: must be 'pressure'"):
        LookaheadPump(gym.make("InflatedBall-v3", action_mode="paddle"))
    with pytest.raises(ValueError, match="span = 0.3, candidates = 1 are out of range"):
        LookaheadPump(gym.make("InflatedBall-v3"), candidates=1)


@pytest.mark.parametrize(("mode", "kind"), [("pressure", LookaheadPump), ("paddle", LookaheadPaddle)])
def test_the_named_lookahead_is_the_action_modes(mode, kind):
    policy = make_policy("lookahead", gym.make("InflatedBall-v3", action_mode=mode))
    assert type(policy) is kind


def test_the_response_analysis_finds_the_crossing_the_slope_and_an_exact_fit():
    """``benchmarks/pump_response.py``'s analysis on a response known in closed form."""
    pump_response = load_benchmark("pump_response")
    amplitudes = np.linspace(-0.3, 0.3, 41)
    curves = np.array([np.clip(2.5 * (amplitudes - u), -0.45, 0.3) for u in (0.05, 0.1, 0.13)])
    curves[1, :] = -0.4  # never reaches the target
    u_star, slope = pump_response.zero_crossings(curves, amplitudes)
    np.testing.assert_allclose(u_star[[0, 2]], [0.05, 0.13], atol=1e-12)
    np.testing.assert_allclose(slope[[0, 2]], 2.5, rtol=1e-12)
    assert np.isnan(u_star[1]) and np.isnan(slope[1])
    features = np.array([[0.1, 1.0], [0.3, 0.0], [-0.2, 2.0], [0.0, 0.5]])
    assert pump_response.residual_sd(0.09 + 0.4 * features[:, 0] - 0.1 * features[:, 1], features) < 1e-15
    assert pump_response.residual_sd(np.array([0.1, 0.1, 0.2, 0.2]), features[:, :0]) == 0.05


@pytest.mark.slow  # 50 s of network fits inside benchmarks/pump_response.py's analysis
def test_the_network_fit_finds_a_dependence_no_linear_fit_finds():
    """``pump_response.network_residual_sd`` out of sample on a target that depends on its input
    through the fractional part of a multiple of it (as the right amplitude does on the landing
    time), where a least-squares line leaves almost all of its scatter (measured: 0.0044 against
    0.027, of 0.028)."""
    pump_response = load_benchmark("pump_response")
    x = np.random.default_rng(1).uniform(0.0, 1.0, (600, 1))
    u_star = 0.1 * ((3.0 * x[:, 0]) % 1.0)
    assert pump_response.residual_sd(u_star, x) > 0.9 * u_star.std()
    assert pump_response.network_residual_sd(u_star, x) < 0.5 * pump_response.residual_sd(u_star, x)
