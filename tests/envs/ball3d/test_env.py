"""InflatedBall3D-v0 and InflatedBall3DPaddle-v0 as Gymnasium and Stable-Baselines3 expect them:
checkers, registration, seeding, copies, pickling, a spawned process, the observation's layout, a
strike's impulse, extreme actions and clear errors."""

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

import ballenv  # noqa: F401  (registers the envs)
from ballenv.envs.ball3d import observation
from ballenv.envs.ball3d.env import InflatedBall3DEnv, ball3d_env

IDS = ("InflatedBall3D-v0", "InflatedBall3DPaddle-v0")


@pytest.mark.parametrize("env_id", IDS)
@pytest.mark.parametrize("render_mode", [None, "rgb_array"])
def test_gymnasium_check_env_passes_with_warnings_as_errors(env_id, render_mode):
    env = gym.make(env_id, render_mode=render_mode)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env.unwrapped, skip_render_check=False)


def test_the_frame_of_a_resting_ball_shows_it_where_the_camera_looks():
    env = gym.make(IDS[1], render_mode="rgb_array", start_height_range=(0.25, 0.26))
    env.reset(seed=0)
    for _ in range(60):  # it settles on the ground
        env.step(np.array([-1.0, 0.0, 0.0]))
    frame = env.render()
    assert frame.shape == (360, 480, 3) and frame.dtype == np.uint8
    ball = ball3d_env(env).ball
    camera = ball3d_env(env)._renderer.camera
    pixel, _ = camera.project(ball.sim.x[0].mean(axis=0))
    col, row = (int(round(v)) for v in pixel)
    colour = frame[row, col].astype(int)
    corner = frame[5, 5].astype(int)  # sky
    assert np.abs(colour - corner).sum() > 60  # the ball, not the sky, at its centre's pixel
    assert np.array_equal(frame, env.render())  # drawing reads state only


@pytest.mark.parametrize("env_id", IDS)
def test_stable_baselines3_check_env_passes(env_id):
    sb3_checker = pytest.importorskip("stable_baselines3.common.env_checker")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sb3_checker.check_env(gym.make(env_id).unwrapped, warn=True)


def test_registered_with_a_time_limit_and_one_id_per_mode():
    for env_id, mode in zip(IDS, ("pressure", "paddle"), strict=True):
        env = gym.make(env_id)
        assert env.spec.max_episode_steps == 1000
        assert ball3d_env(env).config.action_mode == mode
    assert gym.make(IDS[0], action_mode="paddle").unwrapped.config.paddle
    with pytest.raises(TypeError, match="InflatedBall3D"):
        ball3d_env(gym.make("InflatedBall-v3"))


@pytest.mark.parametrize("env_id", IDS)
def test_the_observation_layout_is_declared_once_and_reads_the_state(env_id):
    env = gym.make(env_id)
    obs, info = env.reset(seed=3)
    ball = ball3d_env(env)
    s, n = ball.observation_structure, ball.config.n_vertices
    assert obs.shape == (observation.size(n, ball.config.paddle),) == env.observation_space.shape
    assert s["vertex_position"].stop - s["vertex_position"].start == 3 * n
    centre = obs[s["centre_of_mass_position"]]
    assert abs(centre[2] - obs[s["last_apex"]][0]) < 1e-5  # the start height before the first apex
    assert obs[s["target_height"]][0] == pytest.approx(info["target_height"])
    relative = obs[s["vertex_position"]].reshape(n, 3)
    assert np.abs(relative.mean(axis=0)).max() < 0.01  # about the centre of mass
    assert np.all(obs[s["ground_normal_force"]] == 0.0)  # it starts in flight


@pytest.mark.parametrize("env_id", IDS)
def test_same_seed_same_episode_and_a_deep_copy_steps_alike(env_id):
    def run(env, n=25):
        env.action_space.seed(5)
        return [env.step(env.action_space.sample())[:3] for _ in range(n)]

    a, b = gym.make(env_id), gym.make(env_id)
    oa, _ = a.reset(seed=11)
    ob, _ = b.reset(seed=11)
    assert np.array_equal(oa, ob)
    ra, rb = run(a), run(b)
    assert all(np.array_equal(x[0], y[0]) and x[1:] == y[1:] for x, y in zip(ra, rb, strict=True))
    twin = copy.deepcopy(a.unwrapped)
    action = a.action_space.sample()
    o1, r1, *_ = a.unwrapped.step(action)
    o2, r2, *_ = twin.step(action)
    assert np.array_equal(o1, o2) and r1 == r2


def test_pickled_env_is_the_same_env_and_a_spawned_process_makes_it():
    env = gym.make(IDS[1], target_spot_radius=0.1)
    other = pickle.loads(pickle.dumps(env.unwrapped))
    assert other.config == env.unwrapped.config
    code = (
        "import gymnasium as gym; e = gym.make('ballenv:InflatedBall3DPaddle-v0'); "
        "print(e.reset(seed=0)[0].shape)"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=300, check=True
    )
    assert out.stdout.strip().endswith("(1151,)")


def test_a_strike_delivers_its_impulse_along_its_tilt():
    env = InflatedBall3DEnv(
        action_mode="paddle", start_height_range=(1.2, 1.3), target_height_range=(0.9, 1.0)
    )
    env.reset(seed=0)
    ball = env.ball
    while not ball.in_reach:  # falling toward the paddle's reach
        env.step(np.array([-1.0, 0.0, 0.0]))
    mass = ball.sim.run.steps[0].problem.model.mass
    p0 = mass @ ball.sim.v[0]
    obs, _, _, _, info = env.step(np.array([0.2, 1.0, 0.0]))
    p1 = mass @ ball.sim.v[0]
    gravity = mass.sum() * np.array([0.0, 0.0, -9.81]) * env.dt
    impulse = info["paddle_impulse"]
    assert np.linalg.norm(impulse) == pytest.approx(0.6 * ball.config.paddle_max_impulse)
    tilt = np.arctan2(np.hypot(impulse[0], impulse[1]), -impulse[2])
    assert tilt == pytest.approx(ball.config.paddle_max_tilt) and impulse[0] > 0.0 and impulse[1] == 0.0
    # Newton stops at the fast preset's tolerance: the momentum holds the impulse to 1e-3
    np.testing.assert_allclose(p1 - p0 - gravity, impulse, atol=1e-3 * np.linalg.norm(impulse))
    assert not ball.in_reach  # one strike per flight


@pytest.mark.parametrize("env_id", IDS)
def test_extreme_actions_give_valid_observations_and_bounded_rewards(env_id):
    env = gym.make(env_id)
    env.reset(seed=2)
    rng = np.random.default_rng(0)
    for k in range(150):
        action = rng.choice([-1.0, 1.0], size=env.action_space.shape) * (1.0 + k % 3)
        obs, reward, term, trunc, info = env.step(action)
        assert env.observation_space.contains(obs) and 0.0 <= reward <= 1.0
        assert not info["sim_failure"], info["sim_failure_reason"]
        if term or trunc:
            env.reset()


def test_bad_input_is_a_clear_error():
    with pytest.raises(ValueError, match=r"InflatedBall3D-v0\.paddle_max_tilt = 3"):
        gym.make(IDS[1], paddle_max_tilt=3)
    with pytest.raises(ValueError, match=r"InflatedBall3D-v0\.radius"):
        gym.make(IDS[0], radius=-1.0)
    with pytest.raises(TypeError, match="unknown keyword"):
        gym.make(IDS[0], radious=0.1)
    env = gym.make(IDS[0])
    with pytest.raises(ResetNeeded, match="InflatedBall3D-v0 step"):
        env.unwrapped.step(np.zeros(1))
    env.reset(seed=0)
    with pytest.raises(ValueError, match="InflatedBall3D-v0 step action"):
        env.step(np.array([np.nan]))
