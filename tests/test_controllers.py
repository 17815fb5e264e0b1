"""Pumping works: scripted controllers keep the ball bouncing near a target the uncontrolled ball
cannot keep (it comes to rest)."""

import gymnasium as gym
import numpy as np
import pytest

import ballenv  # noqa: F401  (registers the env)
from ballenv.controllers import PaddleDribble, PressurePump
from ballenv.physics.base.ring import total_mass


def _episode(env, seed, controller, idle):
    obs, info = env.reset(seed=seed)
    if controller is not None:
        controller.reset()
    errors = []
    for _ in range(1000):
        action = controller.act(obs) if controller is not None else idle
        obs, _, terminated, truncated, info = env.step(action)
        if info["apex_count"]:
            errors.append(abs(info["apex_height"] - info["target_height"]) / info["target_height"])
        if terminated or truncated:
            break
    return np.array(errors), info


@pytest.mark.parametrize(
    ("mode", "targets"),
    [("pressure", (0.85, 0.95)), ("paddle", (0.6, 0.7))],
)
def test_scripted_controller_keeps_the_target_the_uncontrolled_ball_cannot(mode, targets):
    env = gym.make("InflatedBall-v3", action_mode=mode, target_height_range=targets)
    structure = env.unwrapped.observation_structure
    config = env.unwrapped.config
    if mode == "pressure":
        controller = PressurePump(structure)
        idle = np.array([0.0], dtype=np.float32)  # constant gas: the initial 30 kPa
    else:
        mass = total_mass(config.ring(config.initial_pressure))
        controller = PaddleDribble(structure, mass, max_impulse=config.paddle_max_impulse)
        idle = np.array([-1.0], dtype=np.float32)  # the paddle never strikes
    controlled_errors = []
    for seed in range(1, 9):  # 4 seeds gave a median of 0.36 once self-contact changed the chaos
        free, free_info = _episode(env, seed, None, idle)
        assert free_info["termination"] == "rest"
        assert free[-3:].mean() > 0.5  # its last bounces are far below the target
        controlled, info = _episode(env, seed, controller, idle)
        assert info["termination"] == ""  # still bouncing at the time limit
        assert len(controlled) >= 10
        controlled_errors.append(controlled[3:].mean())  # after the first bounces
    # pumping is chaotic (the ring's vibrations): most episodes track the target within 20 %
    # (measured: 5 of 8; the other 3 sink into the pump's low-bounce trap, errors 0.53-0.73)
    assert np.median(controlled_errors) < 0.2, controlled_errors


def test_paddle_dribble_strikes_the_first_fall_of_a_ball_released_under_a_high_target():
    """Released at 0.6-0.62 m under a 0.95-1.0 m target, the ball's top is in the paddle's reach
    only on its first fall: the controller strikes then (from the start height) and keeps it up."""
    env = gym.make("InflatedBallPaddle-v3", start_height_range=(0.6, 0.62), target_height_range=(0.95, 1.0))
    config = env.unwrapped.config
    mass = total_mass(config.ring(config.initial_pressure))
    controller = PaddleDribble(env.unwrapped.observation_structure, mass, retention=0.69)
    for seed in range(2):
        obs, _ = env.reset(seed=seed)
        controller.reset()
        first_strike, apexes = None, 0
        for _ in range(1000):
            obs, _, terminated, truncated, info = env.step(controller.act(obs))
            apexes += info["apex_count"]
            if info["paddle_impulse"] > 0.0 and first_strike is None:
                first_strike = apexes
            if terminated or truncated:
                break
        assert first_strike == 0  # before the first flight apex
        assert info["termination"] == ""  # still bouncing at the time limit
