"""agents.wrappers3d.PaddleStrike3D: one agent step a strike of the dribbler, corrected by the agent;
a zero correction is the dribbler to the bit; its rewards are the apexes' combined errors that
agents.evaluate3d scores; a run of train.py behind it is scored by agents.evaluate3d; and
benchmarks/ball3d_strike.py's verdict and learning curves."""

import gymnasium as gym
import numpy as np
import pytest
import yaml

from agents.config import load_hyperparams
from agents.evaluate3d import evaluate3d, run_episode
from agents.policies import Heuristic3DPolicy
from agents.train import parse_args, train
from agents.wrappers3d import CORRECTION, IDLE, PaddleStrike3D
from tests.benchmark_modules import load_benchmark

STEPS = 300  # control steps per episode: about four strikes
SHORT = {"action_mode": "paddle", "max_episode_steps": STEPS}


def wrapped(**kwargs):
    return PaddleStrike3D(gym.make("ballenv:InflatedBall3DPaddle-v0", max_episode_steps=STEPS, **kwargs))


class Playing:
    """A policy that plays ``PaddleStrike3D`` with a fixed correction (the agent's action)."""

    name = "fixed correction"

    def __init__(self, env, correction):
        self.wrapper, self.correction = PaddleStrike3D(env), np.asarray(correction, dtype=np.float32)

    def reset(self, seed):
        self.wrapper.restart()

    def act(self, obs):
        return self.wrapper.act(obs, lambda wrapped_obs: self.correction)


def test_a_zero_correction_plays_the_dribbler_to_the_bit():
    dribbler = evaluate3d("heuristic", SHORT, episodes=2, seed=10_000)
    zero = evaluate3d(lambda env: Playing(env, np.zeros(3)), SHORT, episodes=2, seed=10_000)
    assert zero.combined_errors == dribbler.combined_errors and zero.lengths == dribbler.lengths
    assert min(dribbler.apexes) >= 3


def test_each_agent_step_is_one_strike_of_the_dribblers_action_plus_the_correction():
    env = wrapped()
    obs, _ = env.reset(seed=3)
    assert env.observation_space.contains(obs) and obs.shape == (env.observation_space.shape[0],)
    base = env.base.copy()
    assert base[0] > -1.0  # a decision: the dribbler strikes
    np.testing.assert_array_equal(obs[-3:], base)
    action = np.array([1.0, -1.0, 0.5], dtype=np.float32)
    played = env.strike(action)
    np.testing.assert_allclose(played, np.clip(base + CORRECTION * action, -1.0, 1.0), rtol=0, atol=1e-7)
    taken = []  # the env actions the wrapper plays in one agent step
    inner_step = env.env.step
    env.env.step = lambda a: taken.append(np.array(a)) or inner_step(a)
    _, _, terminated, truncated, _ = env.step(action)
    np.testing.assert_array_equal(taken[0], played)
    assert len(taken) > 10 and all(np.array_equal(a, IDLE) for a in taken[1:])  # idle to the next decision
    in_reach = env.inner_structure["paddle_in_reach"]
    assert terminated or truncated or env.raw[in_reach][0] > 0.5  # it stopped at the next decision


def test_its_rewards_are_the_apex_errors_agents_evaluate3d_scores():
    """A zero correction: each agent step's reward is minus the combined error of the apex after
    its strike, as agents.evaluate3d scores that apex (the apexes before the first strike, which
    no agent's action sets, are in the score only)."""
    env = wrapped()
    env.reset(seed=10_000)
    costs = []
    while True:
        _, reward, terminated, truncated, info = env.step(np.zeros(3, dtype=np.float32))
        costs.append(-float(reward))
        if terminated or truncated:
            break
    assert truncated and costs[-1] == 0.0  # the time limit came before the last strike's apex
    scored = gym.make("ballenv:InflatedBall3DPaddle-v0", max_episode_steps=STEPS)
    heights, spots, _, _ = run_episode(scored, Heuristic3DPolicy(scored), 10_000)
    errors = [h / 0.5 + d / 0.3 for h, d in zip(heights, spots, strict=True)]
    assert len(costs) - 1 >= 3 and len(errors) > len(costs) - 1
    np.testing.assert_allclose(costs[:-1], errors[-(len(costs) - 1) :], rtol=1e-12, atol=0)


def test_the_pressure_mode_is_refused_naming_the_action_mode():
    with pytest.raises(ValueError, match="action_mode = 'pressure' is invalid"):
        PaddleStrike3D(gym.make("ballenv:InflatedBall3D-v0"))


def test_a_sac_run_behind_it_trains_and_is_scored_strike_by_strike(tmp_path):
    args = parse_args([
        "--algo", "sac", "--action-mode", "paddle3d", "--conf-file", "sac_strike3d", "--n-envs", "1",
        "--total-timesteps", "12", "--eval-freq", "6", "--eval-episodes", "1", "--final-episodes", "0",
        "--log-dir", str(tmp_path), "--env-kwargs", '{"max_episode_steps": 400}',
        "--hyperparams", '{"learning_starts": 4, "batch_size": 4, "buffer_size": 100}',
    ])  # fmt: skip
    run = train(args)
    config = yaml.safe_load((run / "config.yml").read_text())
    assert config["env_wrapper"] == "agents.wrappers3d.PaddleStrike3D"
    score = evaluate3d(str(run), {"action_mode": "paddle", "max_episode_steps": 400}, episodes=1)
    assert score.lengths == (400,) and score.apexes[0] >= 4


def test_the_benchmark_says_beat_only_when_the_intervals_are_apart(tmp_path):
    bench = load_benchmark("ball3d_strike")
    rng = np.random.default_rng(0)
    dribbler = [tuple(0.26 + 0.02 * rng.standard_normal(100))]
    better = [tuple(0.15 + 0.02 * rng.standard_normal(100)) for _ in range(3)]
    same = [tuple(0.26 + 0.02 * rng.standard_normal(100)) for _ in range(3)]
    worse = [tuple(0.40 + 0.02 * rng.standard_normal(100)) for _ in range(3)]
    assert bench.compare(dribbler, better).startswith("The trained agents beat the dribbler")
    assert "do not beat the dribbler" in bench.compare(dribbler, same)
    assert bench.compare(dribbler, worse).startswith("The dribbler beats the trained agents")
    run = tmp_path / "sac_paddle3d_seed4"
    (run / "resume").mkdir(parents=True)
    returns = np.array([[1.0, 3.0], [5.0, 5.0]])  # two evaluations of two episodes
    np.savez(run / "evaluations.npz", timesteps=np.array([10, 20]), results=returns)
    (run / "resume" / "state.json").write_text('{"num_timesteps": 25}')
    lines = bench.curves([run], tmp_path / "curve.png")
    assert lines == ["- `sac_paddle3d_seed4`: 10: 2.0, 20: 5.0; stopped at 25 strikes"]
    (run / "model.zip").write_bytes(b"")  # a finished run keeps its last periodic state too
    assert bench.curves([run], tmp_path / "curve.png") == ["- `sac_paddle3d_seed4`: 10: 2.0, 20: 5.0"]
    assert (tmp_path / "curve.png").stat().st_size > 0


def test_the_benchmark_scores_every_policy_on_the_runs_task(tmp_path):
    bench = load_benchmark("ball3d_strike")
    task = {"target_height_range": [0.7, 0.9], "start_height_range": [0.55, 0.65]}
    runs = [tmp_path / f"sac_paddle3d_seed{s}" for s in range(3)]
    for run, kwargs in zip(runs, (task, task, {"start_height_range": [0.5, 0.6]}), strict=True):
        run.mkdir()
        (run / "config.yml").write_text(yaml.safe_dump({"env_kwargs": {**kwargs, "action_mode": "paddle"}}))
    assert bench.run_task(runs[:2]) == task
    with pytest.raises(ValueError, match="sac_paddle3d_seed2"):
        bench.run_task(runs)
    assert bench.task_words(task) == "; `target_height_range=0.7-0.9 m`; `start_height_range=0.55-0.65 m`"
    assert bench.task_words({"pressure_range": [2e4, 9e4]}) == "; `pressure_range=[20000.0, 90000.0]`"
    assert bench.model_path(runs[0], "final") == runs[0] / "model.zip"
    assert bench.model_path(runs[0], "best") == runs[0]  # the run folder: ModelPolicy takes its best


def test_the_reach_task_strikes_before_every_apex():
    """sac_strike3d_reach.yml's task: every start below every target and already in the paddle's
    reach on its first fall, so the dribbler's first decision comes before any apex."""
    kwargs = load_hyperparams("sac", "paddle3d", "sac_strike3d_reach")["env_kwargs"]
    (low, high), (start_low, start_high) = kwargs["target_height_range"], kwargs["start_height_range"]
    assert start_high < low
    env = PaddleStrike3D(gym.make("ballenv:InflatedBall3DPaddle-v0", max_episode_steps=400, **kwargs))
    c = env.config
    first_fall = np.sqrt(2.0 * (start_low - c.radius) / abs(c.gravity)) / c.control_dt  # control steps
    for seed in range(6):
        _, info = env.reset(seed=seed)
        assert 0 < env.steps < first_fall and low <= info["target_height"] <= high
