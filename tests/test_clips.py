"""Frame strips and real-time clips of the env under its scripted controllers (``ballenv.clips``)."""

import pathlib

import numpy as np
import pytest
from PIL import Image

from ballenv.clips import main, record_clip
from ballenv.video import video_info

ROOT = pathlib.Path(__file__).resolve().parents[1]


def test_the_frame_strip_goes_to_out_by_default_not_over_a_tracked_file(tmp_path, monkeypatch, capsys):
    # the default was docs/env.png: a bare `python -m ballenv.clips` rewrote the README's picture
    monkeypatch.chdir(tmp_path)
    main([])
    written = tmp_path / "out" / "env.png"
    assert capsys.readouterr().out.strip() == "out/env.png"
    assert "out/" in (ROOT / ".gitignore").read_text().split()  # git keeps nothing there
    image = np.asarray(Image.open(written).convert("RGB"))
    assert image.shape == (2 * 480, 5 * 480, 3)  # five frames across, both action modes
    assert len(np.unique(image.reshape(-1, 3), axis=0)) > 3


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
