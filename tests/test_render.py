"""The env's renderer: frames without pygame, the window with it, real-time clips, the frame strip."""

import pathlib
import sys

import gymnasium as gym
import numpy as np
import pytest
from PIL import Image

from ballenv.draw import STYLE
from ballenv.render import SIZE, main, record_clip
from ballenv.video import video_info

ROOT = pathlib.Path(__file__).resolve().parents[1]


def test_the_frame_strip_goes_to_out_by_default_not_over_a_tracked_file(tmp_path, monkeypatch, capsys):
    # the default was docs/env.png: a bare `python -m ballenv.render` rewrote the README's picture
    monkeypatch.chdir(tmp_path)
    main([])
    written = tmp_path / "out" / "env.png"
    assert capsys.readouterr().out.strip() == "out/env.png"
    assert "out/" in (ROOT / ".gitignore").read_text().split()  # git keeps nothing there
    image = np.asarray(Image.open(written).convert("RGB"))
    assert image.shape == (2 * 480, 5 * 480, 3)  # five frames across, both action modes
    assert len(np.unique(image.reshape(-1, 3), axis=0)) > 3


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


@pytest.mark.parametrize("frequency", [20.0, 50.0])
def test_an_env_clip_plays_in_simulated_time(tmp_path, frequency):
    # a frame at the reset and one per control step, written at metadata["render_fps"]: frame k
    # plays at k / fps, its simulated time, and the clip lasts the simulated time plus the last frame
    path, infos = record_clip(tmp_path / "clip.mp4", "pressure", seconds=0.5, control_frequency=frequency)
    n, seconds = video_info(path)
    assert n == len(infos) == round(0.5 * frequency) + 1
    np.testing.assert_allclose([info["time"] for info in infos], np.arange(n) / frequency, rtol=1e-12)
    assert seconds == pytest.approx(n / frequency, abs=0.011)  # ffmpeg prints centiseconds
    assert seconds == pytest.approx(infos[-1]["time"] + 1 / frequency, abs=0.011)


def test_cli_writes_a_clip_of_either_mode(tmp_path, capsys):
    main(["--video", str(tmp_path / "paddle.gif"), "--mode", "paddle", "--seconds", "0.2"])
    assert capsys.readouterr().out.strip() == str(tmp_path / "paddle.gif")
    # 100 Hz: the reset and 20 steps; the GIF keeps every second frame, 20 ms each, in real time
    assert video_info(tmp_path / "paddle.gif") == (11, 0.22)
