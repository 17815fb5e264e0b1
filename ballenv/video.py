"""Writing frames (RGB arrays) as a video: MP4 (H.264, imageio-ffmpeg's bundled ffmpeg) or an
animated GIF (Pillow), and reading back a video's frame count and duration.

    write_video(frames, "clip.mp4", fps=100)   # the format from the suffix: .mp4 or .gif
    video_info("clip.mp4")                     # (frames, seconds)

The frames are (H, W, 3) uint8 arrays of one size; ``fps`` (frames per second, a float or a
Fraction) sets the pace, so frames one control step apart at ``fps = 1 / control_dt`` play in
real time. The MP4 is the full-quality video (24-bit colour, every frame); the GIF, for pages that
play only GIFs inline, has 32 colours, frame times in whole centiseconds and at most 50 frames
per second (browsers slow shorter frames down), so a faster clip keeps every second (third...)
frame to stay in real time.
"""

from __future__ import annotations

import itertools
import math
import os
import pathlib
from collections.abc import Iterable
from fractions import Fraction
from types import ModuleType

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .draw import pillow
from .extras import optional_module

FORMATS = ("gif", "mp4")
MP4_CRF = 20  # H.264 constant rate factor: 0 lossless, 23 x264's default, 51 worst
MP4_BLOCK = 16  # px: the MP4's width and height are padded to a multiple of this (H.264 macroblocks)
GIF_COLOURS = 32
GIF_SHORTEST_MS = 20

Path = str | os.PathLike[str]


def _ffmpeg() -> ModuleType:
    return optional_module("imageio_ffmpeg", "MP4 video", "render", "imageio-ffmpeg")


def video_format(path: Path) -> str:
    """``"mp4"`` or ``"gif"`` from the suffix of ``path``; another suffix raises ValueError."""
    fmt = pathlib.Path(path).suffix.lower().lstrip(".")
    if fmt not in FORMATS:
        raise ValueError(f"video path {str(path)!r}: the suffix must be .mp4 or .gif")
    return fmt


def _check_fps(fps: float | Fraction) -> None:
    if not fps > 0 or not np.isfinite(float(fps)):
        raise ValueError(
            f"video fps = {fps!r} is out of range: must be a positive number of frames per second"
        )


def _padded(frame: NDArray[np.uint8], height: int, width: int) -> NDArray[np.uint8]:
    """``frame`` grown to ``height`` x ``width`` pixels by repeating its last row and column."""
    h, w = frame.shape[:2]
    if (h, w) == (height, width):
        return frame
    return np.pad(frame, ((0, height - h), (0, width - w), (0, 0)), mode="edge")


def write_mp4(
    frames: Iterable[ArrayLike], path: Path, fps: float | Fraction, crf: int = MP4_CRF
) -> pathlib.Path:
    """Write ``frames`` (an iterable of (H, W, 3) uint8 arrays) as an H.264 MP4 at ``fps`` frames
    per second; sizes are padded to a multiple of 16 pixels. Returns the path."""
    _check_fps(fps)
    frames = iter(frames)
    first = next(frames, None)
    if first is None:
        raise ValueError("a video needs at least one frame")
    first = np.asarray(first)
    height, width = (-(-n // MP4_BLOCK) * MP4_BLOCK for n in first.shape[:2])
    writer = _ffmpeg().write_frames(
        str(path),
        (width, height),
        fps=Fraction(fps).limit_denominator(10_000),
        codec="libx264",
        quality=None,  # the CRF below instead
        macro_block_size=1,  # padded here: ffmpeg would rescale instead
        ffmpeg_log_level="error",
        output_params=["-crf", str(crf), "-preset", "medium", "-movflags", "+faststart"],
    )
    writer.send(None)  # start ffmpeg
    try:
        for frame in itertools.chain([first], frames):
            frame = np.asarray(frame, dtype=np.uint8)
            if frame.shape[:2] != first.shape[:2]:
                raise ValueError(f"video frames differ in size: {frame.shape[:2]} after {first.shape[:2]}")
            writer.send(np.ascontiguousarray(_padded(frame, height, width)))
    finally:
        writer.close()
    return pathlib.Path(path)


def gif_timing(n_frames: int, fps: float | Fraction) -> tuple[int, list[int]]:
    """``(step, durations)``: a GIF of ``n_frames`` frames at ``fps`` keeps every ``step``-th frame,
    so that none is shorter than 20 ms, and shows kept frame j for ``durations[j]`` ms (whole
    centiseconds), so that it starts at its time (``j * step / fps`` s) to the centisecond."""
    step = max(1, math.ceil(GIF_SHORTEST_MS / 1000 * float(fps) - 1e-9))
    kept = -(-n_frames // step)
    starts_cs = np.rint(np.arange(kept + 1) * step * 100 / float(fps)).astype(int)
    return step, (10 * np.diff(starts_cs)).tolist()


def write_gif(
    frames: Iterable[ArrayLike], path: Path, fps: float | Fraction, colours: int = GIF_COLOURS
) -> pathlib.Path:
    """Write ``frames`` as an animated GIF (``colours`` colours, looping) that plays at ``fps``
    frames per second in real time: faster than 50 fps it keeps every second (third...) frame;
    frame times are whole centiseconds, rounded so that every frame starts on time
    (:func:`gif_timing`). Returns the path."""
    _check_fps(fps)
    Image, _, _ = pillow()
    frames = list(frames)
    if not frames:
        raise ValueError("a video needs at least one frame")
    step, durations = gif_timing(len(frames), fps)
    images = [
        Image.fromarray(np.asarray(f, dtype=np.uint8)).quantize(colors=colours, dither=0)
        for f in frames[::step]
    ]
    images[0].save(path, save_all=True, append_images=images[1:], duration=durations, loop=0, optimize=True)
    return pathlib.Path(path)


def write_video(frames: Iterable[ArrayLike], path: Path, fps: float | Fraction) -> pathlib.Path:
    """Write ``frames`` at ``fps`` as an MP4 or a GIF, by the suffix of ``path``. Returns the path."""
    writer = write_mp4 if video_format(path) == "mp4" else write_gif
    return writer(frames, path, fps)


def video_info(path: Path) -> tuple[int, float]:
    """``(frames, seconds)`` of the video at ``path``: ffmpeg decodes an MP4 (every frame);
    a GIF's frame times are summed."""
    if video_format(path) == "mp4":
        frames, seconds = _ffmpeg().count_frames_and_secs(str(path))
        return int(frames), float(seconds)
    Image, _, _ = pillow()
    with Image.open(path) as gif:
        ms = 0
        for k in range(gif.n_frames):
            gif.seek(k)
            ms += gif.info["duration"]
        return gif.n_frames, ms / 1000.0
