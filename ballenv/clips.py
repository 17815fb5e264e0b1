"""Frame strips and real-time clips of InflatedBall-v3 under its scripted controllers.

    python -m ballenv.clips [--out out/env.png]           # the frame strip (the README's picture)
    python -m ballenv.clips --video out/env.mp4 [--mode paddle] [--seconds 3]   # a real-time clip

The env draws its own frames (``render_mode="rgb_array"``, :mod:`ballenv.envs.render`); this module
plays it under the scripted pump or dribble (:mod:`ballenv.controllers`) and writes what it sees.
"""

from __future__ import annotations

import os
import pathlib
from collections.abc import Iterator, Sequence
from typing import Any

import gymnasium as gym
import numpy as np
from numpy.typing import NDArray

from .controllers import PaddleDribble, PressurePump
from .draw import pillow
from .envs.inflated_ball import ball_env
from .physics.base.ring import total_mass
from .video import write_video


def scripted(mode: str, **env_kwargs: Any) -> tuple[gym.Env[Any, Any], PressurePump | PaddleDribble]:
    """InflatedBall-v3 (``action_mode=mode``, ``rgb_array`` frames) and its scripted controller
    (the pump or the dribble): ``(env, controller)``."""
    env = gym.make("InflatedBall-v3", action_mode=mode, render_mode="rgb_array", **env_kwargs)
    ball = ball_env(env)
    config, structure = ball.config, ball.observation_structure
    if mode == "pressure":
        return env, PressurePump(structure)
    mass = total_mass(config.ring(config.initial_pressure))
    return env, PaddleDribble(structure, mass, max_impulse=config.paddle_max_impulse)


def play(
    env: gym.Env[Any, Any], controller: PressurePump | PaddleDribble, steps: int, seed: int = 3
) -> Iterator[tuple[NDArray[np.uint8], dict[str, Any]]]:
    """Yield ``(frame, info)`` at ``env.reset(seed=seed)`` and after each of ``steps`` steps of
    ``controller`` (``info["time"]``: the frame's simulated time, s); stops when the episode ends."""
    obs, info = env.reset(seed=seed)
    yield _frame(env), info
    for _ in range(steps):
        obs, _, terminated, truncated, info = env.step(controller.act(obs))
        yield _frame(env), info
        if terminated or truncated:
            return


def _frame(env: gym.Env[Any, Any]) -> NDArray[np.uint8]:
    """``env.render()`` of an ``rgb_array`` env: its (H, W, 3) uint8 frame."""
    frame = env.render()
    assert isinstance(frame, np.ndarray)  # rgb_array mode
    return frame


def frame_strip(
    out: str | os.PathLike[str], steps: Sequence[int] = (0, 30, 36, 42, 90), seed: int = 3
) -> str | os.PathLike[str]:
    """Write a PNG strip of frames of both action modes under their scripted controllers: one row
    per mode, one column per control step of ``steps``. Returns ``out``."""
    rows = []
    for mode in ("pressure", "paddle"):
        env, controller = scripted(mode)
        run = play(env, controller, max(steps), seed)
        rows.append(np.concatenate([frame for k, (frame, _) in enumerate(run) if k in steps], axis=1))
        env.close()
    Image, _, _ = pillow()
    Image.fromarray(np.concatenate(rows, axis=0)).save(out)
    return out


def record_clip(
    path: str | os.PathLike[str],
    mode: str = "pressure",
    seconds: float = 3.0,
    seed: int = 3,
    **env_kwargs: Any,
) -> tuple[pathlib.Path, list[dict[str, Any]]]:
    """Write a real-time video (``.mp4`` or ``.gif``) of ``seconds`` of simulated time under the
    scripted controller in ``mode``: a frame at the reset and one per control step, at
    ``metadata["render_fps"]`` (the control frequency), so frame k plays at its simulated time.
    Returns ``(path, infos)``: the frames' step infos (``infos[k]["time"]``, s)."""
    env, controller = scripted(mode, **env_kwargs)
    fps = env.metadata["render_fps"]
    infos: list[dict[str, Any]] = []

    def frames() -> Iterator[NDArray[np.uint8]]:
        for frame, info in play(env, controller, round(seconds * fps), seed):
            infos.append(info)
            yield frame

    try:
        return write_video(frames(), path, fps), infos
    finally:
        env.close()


def main(argv: Sequence[str] | None = None) -> None:
    """``python -m ballenv.clips [--out PATH] [--video PATH --mode MODE --seconds S]``: write the
    frame strip (default ``out/env.png``, outside the tracked files; the README's picture is
    ``--out docs/env.png``), or with ``--video`` a real-time clip (.mp4 or .gif)."""
    import argparse

    parser = argparse.ArgumentParser(
        prog="python -m ballenv.clips", description="Write a frame strip or a clip of InflatedBall-v3."
    )
    parser.add_argument("--out", default="out/env.png", help="PNG file to write (default out/env.png)")
    parser.add_argument("--video", default=None, help="write a clip instead: a .mp4 or .gif file")
    parser.add_argument("--mode", default="pressure", choices=("pressure", "paddle"), help="the clip's mode")
    parser.add_argument(
        "--seconds", type=float, default=3.0, help="simulated seconds of the clip (default 3)"
    )
    args = parser.parse_args(argv)
    out = pathlib.Path(args.video or args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    if args.video:
        record_clip(out, args.mode, args.seconds)
    else:
        frame_strip(out)
    print(out)


if __name__ == "__main__":
    main()


if __name__ == "__main__":
    main()
