"""Video files: frames and seconds read back from the MP4 (ffmpeg) and the GIF equal what was written."""

from fractions import Fraction

import imageio_ffmpeg
import numpy as np
import pytest
from PIL import Image

from ballenv.video import gif_timing, video_format, video_info, write_gif, write_mp4, write_video


def frames(n, height=48, width=64):
    """``n`` frames: a grey level rising frame by frame, a red square moving right."""
    out = []
    for k in range(n):
        frame = np.full((height, width, 3), 40 + 10 * k, dtype=np.uint8)
        frame[10:20, 2 * k : 2 * k + 10] = (200, 60, 40)
        out.append(frame)
    return out


@pytest.mark.parametrize("fps", [25, 100, Fraction(80, 3), 120 / 4.5])
def test_mp4_holds_every_frame_at_its_fps(tmp_path, fps):
    path = write_mp4(iter(frames(12)), tmp_path / "clip.mp4", fps)
    n, seconds = video_info(path)
    assert n == 12
    assert seconds == pytest.approx(12 / float(fps), abs=0.011)  # ffmpeg prints centiseconds
    reader = imageio_ffmpeg.read_frames(str(path))
    meta = next(reader)
    assert meta["fps"] == pytest.approx(float(fps), abs=0.01)
    decoded = [np.frombuffer(b, np.uint8).reshape(48, 64, 3) for b in reader]
    assert len(decoded) == 12
    error = np.abs(decoded[5].astype(int) - frames(12)[5]).mean()
    assert error < 3.0, error  # H.264 at CRF 20: close to the drawn frame


def test_mp4_pads_odd_sizes_to_whole_macroblocks_with_the_edge_pixels(tmp_path):
    odd = frames(3, height=37, width=51)
    path = write_mp4(odd, tmp_path / "odd.mp4", 10)
    reader = imageio_ffmpeg.read_frames(str(path))
    assert next(reader)["size"] == (64, 48)
    first = np.frombuffer(next(reader), np.uint8).reshape(48, 64, 3)
    np.testing.assert_allclose(first[:37, :51].mean(axis=(0, 1)), odd[0].mean(axis=(0, 1)), atol=2)
    np.testing.assert_allclose(first[-1, -1], odd[0][-1, -1], atol=4)


def test_gif_frame_times_add_up_to_the_clip(tmp_path):
    path = write_gif(frames(10), tmp_path / "clip.gif", 20)
    assert video_info(path) == (10, 0.5)
    with Image.open(path) as gif:
        assert gif.info["duration"] == 50 and gif.info["loop"] == 0
    # 30 fps in whole centiseconds: 30 and 40 ms mixed so that each frame starts on time
    step, durations = gif_timing(12, 30)
    assert step == 1 and set(durations) == {30, 40} and sum(durations) == 400
    starts = np.cumsum([0, *durations[:-1]])
    np.testing.assert_allclose(starts, 1000 * np.arange(12) / 30, atol=5)
    assert video_info(write_gif(frames(12), tmp_path / "thirty.gif", 30)) == (12, 0.4)


def test_gif_faster_than_50_fps_drops_frames_to_stay_in_real_time(tmp_path):
    # browsers slow frames under 20 ms down: 100 fps keeps every second frame, 250 every fifth
    assert gif_timing(21, 100) == (2, [20] * 11)
    assert gif_timing(10, 250) == (5, [20, 20])
    assert video_info(write_gif(frames(21), tmp_path / "fast.gif", 100)) == (11, 0.22)


def test_write_video_chooses_by_suffix_and_refuses_what_it_cannot_write(tmp_path):
    assert video_format("a/clip.MP4") == "mp4" and video_format("clip.gif") == "gif"
    assert video_info(write_video(frames(3), tmp_path / "c.gif", 10))[0] == 3
    assert video_info(write_video(frames(3), tmp_path / "c.mp4", 10))[0] == 3
    with pytest.raises(ValueError, match=r"clip\.avi.*\.mp4 or \.gif"):
        write_video(frames(3), tmp_path / "clip.avi", 10)
    for fps in (0, -5, float("nan")):
        with pytest.raises(ValueError, match="fps"):
            write_video(frames(3), tmp_path / "c.mp4", fps)
    for suffix in ("mp4", "gif"):
        with pytest.raises(ValueError, match="at least one frame"):
            write_video(iter([]), tmp_path / f"empty.{suffix}", 10)
    with pytest.raises(ValueError, match="differ in size"):
        write_mp4([*frames(2), frames(1, height=32)[0]], tmp_path / "mixed.mp4", 10)
