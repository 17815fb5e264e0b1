"""The env's renderer: frames without pygame, the window with it."""

import sys

import gymnasium as gym
import numpy as np

from ballenv.draw import STYLE
from ballenv.envs.render import SIZE


def test_rgb_array_frames_need_no_pygame(monkeypatch):
    monkeypatch.setitem(sys.modules, "pygame", None)  # `import pygame` raises ImportError
    env = gym.make("InflatedBall-v3", action_mode="paddle", render_mode="rgb_array")
    env.reset(seed=0)
    frame = env.render()
    assert frame.shape == (SIZE, SIZE, 3) and frame.dtype == np.uint8
    for colour in (STYLE.ring(0), STYLE.ground, STYLE.target, STYLE.paddle):
        assert np.all(frame == colour, axis=-1).sum() > 50, colour
    env.close()


def test_human_mode_shows_the_same_frame_in_a_window(monkeypatch):
    monkeypatch.setenv("SDL_VIDEODRIVER", "dummy")
    import pygame

    env = gym.make("InflatedBall-v3", render_mode="human")
    env.reset(seed=0)  # human mode draws at reset and at each step
    shown = np.transpose(pygame.surfarray.array3d(pygame.display.get_surface()), (1, 0, 2))
    renderer = env.unwrapped._renderer
    np.testing.assert_array_equal(shown, renderer.frame(env.unwrapped._batch, 0))
    assert env.render() is None
    env.close()
    assert not pygame.display.get_init()


def test_the_last_apex_shown_is_the_last_flight_apex_between_apexes():
    """The overlay's "last apex" holds the height of the last flight apex over the steps after it
    (the task's per-step apex height is 0 at every step without an apex)."""
    from ballenv.controllers import PressurePump
    from ballenv.envs.render import BallRenderer

    env = gym.make("InflatedBall-v3", render_mode="rgb_array")
    ball = env.unwrapped
    pump = PressurePump(ball.observation_structure)
    obs, _ = env.reset(seed=3)
    start = obs[ball.observation_structure["last_apex"]][0]
    assert f"last apex {start:.2f} m" in BallRenderer._labels(ball._batch, 0)[2]  # the start height
    apexes = []
    for _ in range(400):
        obs, _, terminated, truncated, info = env.step(pump.act(obs))
        if info["apex_count"]:
            apexes.append(info["apex_height"])
        elif apexes:  # a step after an apex, without one
            break
        assert not (terminated or truncated)
    assert apexes and apexes[-1] > 0.3
    label = BallRenderer._labels(ball._batch, 0)[2]
    assert f"last apex {apexes[-1]:.2f} m" in label, label
    assert env.render().shape == (SIZE, SIZE, 3)
    env.close()
