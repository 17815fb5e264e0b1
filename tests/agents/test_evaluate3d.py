"""agents.evaluate3d: the 3-D ball's height-and-spot errors per episode, reproducible, with missed
apexes counted; each apex's control step, and benchmarks/ball3d_headroom.py's split of an episode's
apexes at the dribbler's first strike; and PPO and SAC runs of train.py on InflatedBall3DPaddle-v0
scored by it."""

import math

import gymnasium as gym
import numpy as np
import pytest
import yaml

from agents.evaluate3d import apex_records, evaluate3d, main, run_episode
from agents.policies import Heuristic3DPolicy, IdlePolicy
from agents.train import parse_args, train
from tests.benchmark_modules import load_benchmark

SHORT = {"action_mode": "paddle", "max_episode_steps": 120}


def test_the_same_seeds_give_the_same_scores_and_the_errors_follow_their_definition():
    first = evaluate3d("random", SHORT, episodes=2, seed=5)
    again = evaluate3d("random", SHORT, episodes=2, seed=5)
    assert first == again
    assert first.policy == "random" and len(first.height_errors) == 2
    for h, d, combined in zip(first.height_errors, first.spot_distances, first.combined_errors, strict=True):
        assert combined == pytest.approx(h / 0.5 + d / 0.3)  # the env's default margins
        assert 0.0 <= h and 0.0 <= d < 2.0 * math.sqrt(2.0)


def test_an_episode_that_ends_at_rest_counts_its_missed_apexes():
    """A lossy ball (damping 300 /s) dropped from 0.3 m with no strike rests within 3 s: each
    flight time at the target left until the 4 s limit counts a height error of 1 and the distance
    where it stopped."""
    env = gym.make(
        "ballenv:InflatedBall3DPaddle-v0",
        max_episode_steps=400,
        damping=300.0,
        start_height_range=(0.3, 0.32),
    )
    heights, spots, length, _ = run_episode(env, IdlePolicy(env), 0)
    ball = env.unwrapped.ball
    flight = 2.0 * math.sqrt(2.0 * (ball.target - ball.config.radius) / ball.config.gravity)
    missed = round((400 - length) * 0.01 / flight)
    assert ball.end == "rest" and missed >= 1
    assert heights[-missed:] == [1.0] * missed and max(heights[:-missed]) < 1.0
    assert len(set(spots[-missed:])) == 1


def test_each_apex_has_its_control_step_and_the_headroom_split_cuts_at_the_first_strike():
    """Episode 10,003 starts above its target: the dribbler idles through two apexes (about steps 85
    and 166), strikes at step 167, and sets the third apex."""
    env = gym.make("ballenv:InflatedBall3DPaddle-v0", max_episode_steps=250)
    policy = Heuristic3DPolicy(env)
    apexes, length, _ = apex_records(env, policy, 10_003)
    heights, spots, _, _ = run_episode(env, policy, 10_003)
    assert [a.height for a in apexes] == heights and [a.distance for a in apexes] == spots
    steps = [a.step for a in apexes]
    assert steps == sorted(set(steps)) and 0 < steps[0] and steps[-1] <= length == 250
    bench = load_benchmark("ball3d_headroom")
    rows = bench.split(10_003, 250, {})
    assert [after for *_, after in rows] == [False, False, True]
    assert [(h, d) for h, d, _ in rows] == list(zip(heights, spots, strict=True))
    expected = np.mean(heights) / 0.5 + np.mean(spots) / 0.3
    assert bench.combined(rows, 1.0) == pytest.approx(expected)
    assert bench.combined(rows, 0.0) == pytest.approx(
        np.sum(heights[:2]) / 3 / 0.5 + np.sum(spots[:2]) / 3 / 0.3
    )
    text = bench.verdict(0.2, 0.25, 0.19)
    assert "ends at 0.250 (not below it)" in text and "at 0.190 (below it)" in text


def test_the_pump_and_constant_gas_run_in_pressure_mode(capsys):
    main(["heuristic", "--action-mode", "pressure", "--episodes", "1", "--max-episode-steps", "30"])
    assert "pump: height error" in capsys.readouterr().out
    assert evaluate3d("idle", {"action_mode": "pressure", "max_episode_steps": 30}, 1).spot_distances == (
        0.0,
    )


TINY = {
    "ppo": '{"n_steps": 64, "batch_size": 64}',
    "sac": '{"learning_starts": 64, "batch_size": 64, "buffer_size": 1000}',
}


@pytest.mark.parametrize("algo", ["ppo", "sac"])
def test_an_agent_trains_on_the_3d_paddle_and_its_best_model_scores(algo, tmp_path, capsys):
    args = parse_args([
        "--algo", algo, "--action-mode", "paddle3d", "--n-envs", "1", "--total-timesteps", "128",
        "--eval-freq", "64", "--eval-episodes", "1", "--final-episodes", "1", "--log-dir", str(tmp_path),
        "--env-kwargs", '{"max_episode_steps": 40}', "--hyperparams", TINY[algo],
    ])  # fmt: skip
    run = train(args)
    assert "python -m agents.evaluate3d" in capsys.readouterr().out  # no ring scoreboard for 3-D
    config = yaml.safe_load((run / "config.yml").read_text())
    assert config["env_id"] == "ballenv:InflatedBall3DPaddle-v0" and config["env_wrapper"] is None
    assert config["env_kwargs"]["action_mode"] == "paddle"
    assert np.load(run / "evaluations.npz")["timesteps"].size >= 1
    score = evaluate3d(str(run), {"action_mode": "paddle", "max_episode_steps": 40}, episodes=1)
    assert score.policy.startswith("trained") and score.lengths[0] <= 40
