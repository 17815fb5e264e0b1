"""agents.imitation: the lookahead's demonstrations, their returns, and a PPO policy cloned from them
before reinforcement learning (train.py --demonstrations)."""

import json
import pathlib
import subprocess
import sys

import numpy as np
import pytest
import yaml

import ballenv  # noqa: F401  (registers the env)
from agents.imitation import Demonstrations, discounted_returns, pretrain, record
from agents.lookahead import zero_crossing
from agents.train import main as train_main
from agents.train import make_envs

ROOT = pathlib.Path(__file__).resolve().parents[2]
WRAPPER = "agents.wrappers.PumpAmplitude"
SHORT = {"action_mode": "pressure", "max_episode_steps": 150}  # about two bounces an episode


@pytest.fixture(scope="module")
def demonstrations():
    return record(SHORT, episodes=2, wrapper=WRAPPER, progress=False)


def test_the_zero_crossing_of_a_line_is_its_root_and_slope():
    amplitudes = np.linspace(-0.3, 0.3, 41)
    crossing, slope = zero_crossing(2.0 * (amplitudes - 0.0412), amplitudes)
    assert crossing == pytest.approx(0.0412) and slope == pytest.approx(2.0)
    assert np.isnan(zero_crossing(amplitudes + 1.0, amplitudes)).all()  # above zero throughout


def test_demonstrations_are_the_lookahead_playing_whole_bounces(demonstrations):
    d = demonstrations
    n = len(d.actions)
    assert d.observations.shape == d.next_observations.shape == (n, 11) and d.actions.shape == (n, 1)
    assert n >= 4 and np.all(np.abs(d.actions) <= 1.0)
    assert d.ended.sum() == 2 and d.ended[-1] and not d.terminated.any()  # two episodes to the limit
    within = ~d.ended[:-1]
    np.testing.assert_array_equal(d.next_observations[:-1][within], d.observations[1:][within])
    assert np.all(d.rewards > 0.0)  # a bounce's summed per-step reward in [0, 1] a step
    # the demonstrated amplitude is where the lookahead's next apex crosses the target: in the
    # middle of the span, not at its ends (the pump's tuned amplitude is about 0.16)
    assert 0.1 < np.median(np.abs(d.actions)) < 0.9


def test_discounted_returns_continue_a_cut_episode_with_its_tail_and_stop_a_terminated_one():
    rewards = np.array([1.0, 2.0, 3.0, 4.0])
    ended = np.array([False, True, False, True])
    tail = np.array([0.0, 10.0, 0.0, 0.0])  # the first episode cut short, the second terminated
    got = discounted_returns(rewards, ended, tail, gamma=0.5)
    np.testing.assert_allclose(got, [1.0 + 0.5 * (2.0 + 5.0), 2.0 + 5.0, 3.0 + 2.0, 4.0])


def test_a_demonstration_file_round_trips_and_a_foreign_one_is_refused(demonstrations, tmp_path):
    path = tmp_path / "d.npz"
    demonstrations.save(path)
    again = Demonstrations.load(path)
    np.testing.assert_array_equal(again.actions, demonstrations.actions)
    foreign = {**demonstrations.__dict__, "wrapper": "agents.wrappers.ResidualPump"}
    np.savez(tmp_path / "other.npz", **foreign)
    with pytest.raises(ValueError, match="'agents.wrappers.ResidualPump' is invalid: the demonstrated tasks"):
        Demonstrations.load(tmp_path / "other.npz")


def test_pretraining_clones_a_known_policy_and_its_value(demonstrations):
    """Demonstrations relabelled with a smooth function of the observation, and a reward of that
    function plus 1 for a transition that ends an episode cut short in the state it started from:
    the cloned mean action follows the function, and the value of a state is ``r / (1 - gamma)``
    in normalised rewards."""
    from stable_baselines3 import PPO

    gamma = 0.5
    envs = make_envs(SHORT, 1, seed=0, normalize=True, gamma=gamma, wrapper=WRAPPER)
    model = PPO("MlpPolicy", envs, gamma=gamma, n_steps=64, batch_size=64, seed=0, device="cpu")
    rows = np.concatenate([demonstrations.observations] * 20)  # more samples of the same states
    label = np.tanh(rows[:, 7:8] / rows[:, 6:7] - 1.0).astype(np.float32)  # of apex over target
    reward = 1.0 + label[:, 0].astype(float)
    cut = np.ones(len(rows), dtype=bool)
    fit = pretrain(model, envs, Demonstrations(WRAPPER, rows, label, reward, rows, ~cut, cut))
    assert fit["action_mse"] < 1e-3
    mean, _ = model.predict(envs.normalize_obs(rows), deterministic=True)
    np.testing.assert_allclose(mean, np.clip(label, -1, 1), atol=0.05)
    values = model.policy.predict_values(model.policy.obs_to_tensor(envs.normalize_obs(rows))[0])
    expected = envs.normalize_reward(reward) / (1.0 - gamma)
    np.testing.assert_allclose(values.detach().numpy()[:, 0], expected, rtol=0.1)
    envs.close()


def test_train_pretrains_on_demonstrations_and_records_them(demonstrations, tmp_path):
    path = tmp_path / "d.npz"
    demonstrations.save(path)
    hyper = {"env_wrapper": WRAPPER, "n_steps": 8, "batch_size": 8, "n_epochs": 1, "gamma": 0.9}
    command = [
        sys.executable, str(ROOT / "train.py"), "--n-envs", "1", "--total-timesteps", "8",
        "--eval-freq", "8", "--eval-episodes", "1", "--final-episodes", "1", "--no-baselines",
        "--log-dir", str(tmp_path / "runs"), "--env-kwargs", json.dumps({"max_episode_steps": 150}),
        "--hyperparams", json.dumps(hyper), "--demonstrations", str(path),
    ]  # fmt: skip
    done = subprocess.run(command, cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    assert f"pretrained on {len(demonstrations.actions)} demonstrated bounces" in done.stdout
    run = tmp_path / "runs" / "ppo_pressure_seed0"
    config = yaml.safe_load((run / "config.yml").read_text())
    assert config["demonstrations"] == str(path)
    # the cloned policy is evaluated before the first update: the learning curve starts from it
    np.testing.assert_array_equal(np.load(run / "evaluations.npz")["timesteps"], [0, 8])


def test_demonstrations_are_refused_for_another_task(demonstrations, tmp_path):
    path = tmp_path / "d.npz"
    demonstrations.save(path)
    runs = tmp_path / "runs"
    with pytest.raises(SystemExit) as stop:
        train_main(["--demonstrations", str(path), "--log-dir", str(runs)])  # behind BallStateObservation
    needs = "--demonstrations needs --algo ppo and an env_wrapper of its --action-mode"
    assert needs in str(stop.value.code)
    with pytest.raises(SystemExit) as stop:
        hyper = json.dumps({"env_wrapper": WRAPPER})
        train_main(
            ["--demonstrations", str(tmp_path / "none.npz"), "--hyperparams", hyper, "--log-dir", str(runs)]
        )
    assert "--demonstrations = " in str(stop.value.code) and "none.npz" in str(stop.value.code)
    assert not runs.exists()


def test_paddle_demonstrations_are_the_lookahead_striking():
    """The paddle's task: one correction of the scripted strike a flight, observed with the rotation
    phases, spin and scripted strike (26 entries); the demonstrated correction is where the trend
    of the next apex crosses the target, inside the action's range, and each bounce's reward is
    its apex's tolerance."""
    d = record(SHORT, episodes=1, wrapper="agents.wrappers.PaddleStrike", progress=False)
    n = len(d.actions)
    assert d.wrapper == "agents.wrappers.PaddleStrike" and d.observations.shape == (n, 26) and n >= 2
    np.testing.assert_array_equal(d.next_observations[:-1], d.observations[1:])
    assert np.all(np.abs(d.actions) < 1.0) and np.all((0.0 <= d.rewards) & (d.rewards <= 1.0))
    assert np.median(d.rewards) > 0.5  # the lookahead's bounces land near the target


def test_demonstrations_recorded_in_processes_are_the_serial_ones(demonstrations):
    from agents.imitation import record_in_parallel

    parallel = record_in_parallel(SHORT, episodes=2, seed=0, wrapper=WRAPPER, workers=2)
    assert parallel.wrapper == demonstrations.wrapper
    for name in ("observations", "actions", "rewards", "next_observations", "terminated", "ended"):
        np.testing.assert_array_equal(getattr(parallel, name), getattr(demonstrations, name), err_msg=name)
    other = Demonstrations(**{**demonstrations.__dict__, "wrapper": "agents.wrappers.PumpApex"})
    with pytest.raises(ValueError, match="several tasks"):
        Demonstrations.concatenate([demonstrations, other])
