"""InflatedBall-v3 as Gymnasium and Stable-Baselines3 expect it: checkers, seeding, pickling,
clear errors (extreme actions: tests/stability/test_env_extreme_actions.py)."""

import copy
import pickle
import subprocess
import sys
import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.error import ResetNeeded
from gymnasium.utils.env_checker import check_env
from gymnasium.wrappers import RenderCollection

import ballenv  # noqa: F401  (registers the env)
from ballenv.envs.inflated_ball import InflatedBallEnv, ball_env
from ballenv.envs.vector import InflatedBallVectorEnv

MODES = ("pressure", "paddle")


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("render_mode", [None, "rgb_array", "human"])
def test_gymnasium_check_env_passes_with_warnings_as_errors(mode, render_mode):
    env = gym.make("InflatedBall-v3", action_mode=mode, render_mode=render_mode)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env.unwrapped, skip_render_check=False)
    env.close()


@pytest.mark.parametrize("mode", MODES)
def test_stable_baselines3_check_env_passes(mode):
    sb3_checker = pytest.importorskip("stable_baselines3.common.env_checker")
    env = InflatedBallEnv(action_mode=mode)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sb3_checker.check_env(env, warn=True)


def test_registered_under_both_ids_with_a_time_limit():
    for env_id in ("InflatedBall-v3", "ballenv:InflatedBall-v3"):
        env = gym.make(env_id)
        assert env.spec.max_episode_steps == 1000
        assert isinstance(env.unwrapped, InflatedBallEnv)
    ballenv.register_envs()  # repeatable
    assert gym.spec("InflatedBall-v3").entry_point == "ballenv.envs.inflated_ball:InflatedBallEnv"
    older = ("InflatedBall-v0", "InflatedBall-v1", "InflatedBallPaddle-v1", "InflatedBall-v2")
    for old in (*older, "InflatedBallPaddle-v2"):  # older dynamics
        assert old not in gym.registry


def test_one_id_per_action_mode_and_a_keyword_overrides_it():
    assert gym.make("InflatedBall-v3").unwrapped.config.action_mode == "pressure"
    paddle = gym.make("ballenv:InflatedBallPaddle-v3")
    assert paddle.unwrapped.config.action_mode == "paddle" and paddle.spec.max_episode_steps == 1000
    assert "paddle_height" in paddle.unwrapped.observation_structure
    assert gym.make("InflatedBall-v3", action_mode="paddle").unwrapped.config.action_mode == "paddle"
    venv = gym.make_vec("InflatedBallPaddle-v3", num_envs=2, vectorization_mode="vector_entry_point")
    assert venv.unwrapped.config.action_mode == "paddle"


def _rollout(env, seed, steps, actions=None):
    obs, _ = env.reset(seed=seed)
    env.action_space.seed(seed)
    out = [obs]
    rewards = []
    for k in range(steps):
        a = env.action_space.sample() if actions is None else actions[k]
        obs, reward, terminated, truncated, _ = env.step(a)
        out.append(obs)
        rewards.append(reward)
        if terminated or truncated:
            obs, _ = env.reset()
            out.append(obs)
    return np.array(out), np.array(rewards)


@pytest.mark.parametrize("mode", MODES)
def test_same_seed_gives_identical_rollouts(mode):
    a = _rollout(gym.make("InflatedBall-v3", action_mode=mode), 7, 200)
    b = _rollout(gym.make("InflatedBall-v3", action_mode=mode), 7, 200)
    np.testing.assert_array_equal(a[0], b[0])
    np.testing.assert_array_equal(a[1], b[1])
    c = _rollout(gym.make("InflatedBall-v3", action_mode=mode), 8, 200)
    assert not np.array_equal(a[0][0], c[0][0])


def test_pickle_round_trip_keeps_the_arguments_and_the_dynamics():
    env = InflatedBallEnv(action_mode="paddle", target_height_range=(0.6, 0.7), damping=5.0)
    clone = pickle.loads(pickle.dumps(env))
    assert clone.config == env.config
    actions = np.random.default_rng(0).uniform(-1, 1, (150, 1)).astype(np.float32)
    a = _rollout(env, 3, 150, actions)
    b = _rollout(clone, 3, 150, actions)
    np.testing.assert_array_equal(a[0], b[0])


def test_step_returns_new_arrays_and_python_scalars():
    env = InflatedBallEnv()
    first, _ = env.reset(seed=0)
    obs, reward, terminated, truncated, info = env.step(np.array([0.2], dtype=np.float32))
    assert obs is not first and not np.shares_memory(obs, first)
    assert type(reward) is float and type(terminated) is bool and type(truncated) is bool
    terms = [v for k, v in info.items() if k.startswith("reward_")]
    assert reward == pytest.approx(sum(terms), abs=1e-12)


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"action_mode": "kick"}, "action_mode"),
        ({"fidelity": "ultra"}, "fidelity"),
        ({"control_frequency": float("nan")}, "control_frequency"),
        ({"target_height_range": (1.0, 0.5)}, "target_height_range"),
        ({"pressure_range": (10e3, 1e9)}, "pressure_range"),
        ({"initial_pressure": 5e3}, "initial_pressure"),
        ({"youngs_modulus": -1.0}, "youngs_modulus"),
        ({"render_mode": "ascii"}, "render_mode"),
    ],
)
def test_invalid_arguments_raise_value_error_naming_the_field(kwargs, field):
    with pytest.raises(ValueError, match=field):
        InflatedBallEnv(**kwargs)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"pressure_range": (10e3, 5e6)}, r"pressure_range = \(10000\.0, 5000000\.0\) .* 5e\+06 Pa"),
        ({"action_mode": "paddle", "initial_pressure": 3e6}, r"initial_pressure = 3000000\.0 .* 3e\+06 Pa"),
        ({"youngs_modulus": 1e5}, r"pressure_range = \(10000\.0, 50000\.0\) .* 50000 Pa"),
    ],
)
def test_a_pressure_that_bursts_the_ball_is_reported_by_the_env_keyword(kwargs, message):
    # was "Ring.pressure = ... is out of range", a name the env's user never wrote
    held = r"83736\.5" if "youngs_modulus" not in kwargs else r"837\.365"
    with pytest.raises(ValueError, match=rf"^InflatedBall-v3\.{message} must be at most {held} Pa") as err:
        InflatedBallEnv(**kwargs)
    assert "bursts" in str(err.value) and "Ring." not in str(err.value)
    with pytest.raises(
        ValueError, match=r"^InflatedBall-v3\.thickness = 0\.2 is out of range: .*below radius"
    ):
        InflatedBallEnv(thickness=0.2)


def test_step_or_render_before_reset_asks_for_a_reset():
    # the unwrapped env (gym.make's OrderEnforcing wrapper says the same); was a ZeroDivisionError
    env = InflatedBallEnv(render_mode="rgb_array")
    with pytest.raises(ResetNeeded, match=r"InflatedBall-v3 step\(\) was called before reset\(\)"):
        env.step(np.zeros(1, dtype=np.float32))
    with pytest.raises(ResetNeeded, match=r"render\(\) was called before reset\(\)"):
        env.render()
    env.reset(seed=0)
    obs, reward, *_ = env.step(np.zeros(1, dtype=np.float32))
    assert np.all(np.isfinite(obs)) and 0.0 <= reward <= 1.0
    assert env.render().shape == (480, 480, 3)
    clone = pickle.loads(pickle.dumps(env))  # a fresh env: it needs its own reset
    with pytest.raises(ResetNeeded):
        clone.step(np.zeros(1, dtype=np.float32))


def test_invalid_action_raises_and_out_of_range_actions_are_clipped():
    env = InflatedBallEnv()
    env.reset(seed=0)
    with pytest.raises(ValueError, match="action"):
        env.step(np.array([np.nan], dtype=np.float32))
    env.step(np.array([5.0], dtype=np.float32))
    assert env._batch.task.setpoint[0] == pytest.approx(30e3 + env.config.pressure_rate * env.dt)


def test_rgb_array_render_is_an_image_and_opens_no_window():
    import pygame

    env = gym.make("InflatedBall-v3", action_mode="paddle", render_mode="rgb_array")
    env.reset(seed=0)
    env.step(np.array([1.0], dtype=np.float32))
    frame = env.render()
    assert frame.dtype == np.uint8 and frame.ndim == 3 and frame.shape[2] == 3
    assert len(np.unique(frame.reshape(-1, 3), axis=0)) > 3  # ring, ground, text drawn
    assert not pygame.display.get_init()


@pytest.mark.parametrize("frequency", [20.0, 50.0, 100.0, 250.0])
def test_videos_play_in_real_time_one_frame_per_control_step(frequency):
    # RecordVideo writes the frames it collects at metadata["render_fps"]; RenderCollection collects
    # them the same way (one per reset and step) without a video encoder
    env = RenderCollection(gym.make("InflatedBall-v3", control_frequency=frequency, render_mode="rgb_array"))
    assert env.metadata["render_fps"] == frequency
    env.reset(seed=0)
    steps = 12
    for _ in range(steps):
        *_, info = env.step(np.zeros(1, dtype=np.float32))
    frames = env.render()
    assert len(frames) == steps + 1
    frames_per_simulated_second = steps / info["time"]
    assert frames_per_simulated_second == pytest.approx(env.metadata["render_fps"], rel=1e-12)
    vector = InflatedBallVectorEnv(num_envs=1, num_threads=1, control_frequency=frequency)
    assert vector.metadata["render_fps"] == frequency
    vector.close()


def test_pressure_actions_move_the_energy_budget_and_reset_starts_a_new_one():
    env = InflatedBallEnv(action_mode="pressure")
    env.reset(seed=3)
    energy = env._batch.state.energy[0]
    assert energy[2] == energy[0]  # budget = energy at the start
    start = float(energy[2])
    for _ in range(20):
        env.step(np.array([1.0], dtype=np.float32))  # pump: actuation work raises the budget
    assert energy[2] > start
    assert energy[0] <= energy[2] + 1e-12 * abs(energy[2])  # the energy never above it
    raised = energy[2]
    env.reset(seed=4)
    assert energy[2] == energy[0] != raised
    assert np.all(env._batch.clocks[0, 2:] == 0.0)  # the run's energy tallies restart too


def test_ball_env_finds_the_env_under_wrappers_and_refuses_other_envs():
    env = RenderCollection(gym.make("InflatedBall-v3", render_mode="rgb_array"))
    assert isinstance(ball_env(env), InflatedBallEnv) and ball_env(env) is env.unwrapped
    with pytest.raises(TypeError, match="not an InflatedBall env"):
        ball_env(gym.make("CartPole-v1"))


@pytest.mark.parametrize("env_id", ["InflatedBall-v3", "InflatedBallPaddle-v3"])
def test_a_deep_copy_mid_episode_steps_as_the_original(env_id):
    env = gym.make(env_id).unwrapped
    env.reset(seed=3)
    rng = np.random.default_rng(0)
    for _ in range(20):
        env.step(rng.uniform(-1, 1, 1).astype(np.float32))
    twin = copy.deepcopy(env)
    for _ in range(40):
        action = rng.uniform(-1, 1, 1).astype(np.float32)
        first, second = env.step(action), twin.step(action)
        np.testing.assert_array_equal(first[0], second[0])
        assert first[1:4] == second[1:4]
        if first[2]:
            break
    np.testing.assert_array_equal(env.reset()[0], twin.reset()[0])  # the random generator too


def test_the_pressure_mode_takes_any_control_rate_the_paddle_one_its_strike():
    gym.make("InflatedBall-v3", control_frequency=500.0).close()  # no strike in this mode
    with pytest.raises(ValueError, match="paddle_strike_duration = 0.003 is out of range"):
        gym.make("InflatedBallPaddle-v3", control_frequency=500.0)


WITHOUT_PYGAME = """
import sys

class Blocker:
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] == "pygame":
            raise ModuleNotFoundError("No module named 'pygame' (blocked)", name=name)

sys.meta_path.insert(0, Blocker())
import gymnasium as gym
from gymnasium.utils.env_checker import check_env
import ballenv

env = gym.make("InflatedBall-v3")
assert env.unwrapped.metadata["render_modes"] == ["rgb_array"], env.unwrapped.metadata
check_env(env.unwrapped)  # renders every offered mode
from ballenv.envs.inflated_ball import InflatedBallEnv

try:
    InflatedBallEnv(render_mode="human")
except ImportError as err:
    assert "pygame-ce" in str(err), err
else:
    raise AssertionError("human mode without pygame")
print("ok")
"""


def test_gymnasiums_checker_passes_without_the_window_extra():
    out = subprocess.run([sys.executable, "-c", WITHOUT_PYGAME], capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.strip().endswith("ok")
