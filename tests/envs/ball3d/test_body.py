"""BodyObservation: the 3-D ball seen as a body (centre, velocity, spin, gas, targets)."""

import gymnasium as gym
import numpy as np

import ballenv  # noqa: F401  (registers the envs)
from ballenv.envs.ball3d.body import BodyObservation, angular_velocity
from ballenv.shell import icosphere


def test_the_spin_of_a_rigid_rotation_is_its_angular_velocity():
    r = icosphere(2).vertices * 0.12
    mass = np.random.default_rng(0).uniform(1e-3, 5e-3, len(r))
    r = r - mass @ r / mass.sum()
    omega = np.array([3.0, -7.0, 11.0])
    np.testing.assert_allclose(angular_velocity(mass, r, np.cross(omega, r)), omega, rtol=1e-12)


def test_the_body_observation_keeps_the_fixed_fields_and_adds_spin_and_ground_force():
    env = BodyObservation(gym.make("InflatedBall3DPaddle-v0"))
    obs, _ = env.reset(seed=1)
    s = env.observation_structure
    assert "vertex_position" not in s and list(s)[-2:] == ["spin", "ground_force"]
    assert obs.shape == env.observation_space.shape == (s["ground_force"].stop,)
    assert env.observation_space.contains(obs)
    assert np.abs(obs[s["spin"]]).max() < 1e-3 and obs[s["ground_force"]][0] == 0.0  # in flight, no spin
    inner = env.unwrapped.observation_structure
    full = env.unwrapped.ball.observe()
    assert np.array_equal(obs[s["target_spot"]], full[inner["target_spot"]])
    for _ in range(40):
        obs, *_ = env.step(np.array([-1.0, 0.0, 0.0]))
        assert env.observation_space.contains(obs)
