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
