"""Drawing an env's ball to an RGB array (:mod:`ballenv.draw`, Pillow), a pygame window or a video.

The renderer only reads state: the ring's nodes, its ground reactions, the gas pressure, the
target and the paddle. The view follows the ball horizontally and spans the arena's lower part.
``rgb_array`` frames need Pillow only; the ``human`` window shows the same frames with pygame-ce.

    python -m ballenv.render [--out out/env.png]           # the frame strip (the README's picture)
    python -m ballenv.render --video out/env.mp4 [--mode paddle] [--seconds 3]   # a real-time clip
"""

from __future__ import annotations

import os
import pathlib
from collections.abc import Iterator, Sequence
from types import ModuleType
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from .draw import STYLE, Canvas, Style, View, pillow
from .envs.batch import MODE_PADDLE, BallBatch, env_model
from .extras import optional_module
from .physics.effects.gas import ring_pressure

if TYPE_CHECKING:
    import gymnasium as gym

    from .controllers import PaddleDribble, PressurePump
    from .envs.config import BallEnvConfig

SIZE = 480  # pixels, square
FONT_SIZE = 15  # pixels
LINE_SPACING = 18  # pixels between the text lines


def _pygame() -> ModuleType:
    return optional_module("pygame", "the human render mode", "render", "pygame-ce")


class BallRenderer:
    """Draws env ``e`` of a :class:`~ballenv.envs.batch.BallBatch`.

    ``mode="rgb_array"`` returns a (480, 480, 3) uint8 array and opens no window; ``mode="human"``
    shows the frame in a pygame window paced to ``fps`` (frames per second).
    """

    def __init__(self, config: BallEnvConfig, mode: str, fps: float, style: Style = STYLE) -> None:
        self.config = config
        self.mode = mode
        self.fps = fps
        self.style = style
        self.view_height = max(1.5, config.target_height_range[1] + 4.0 * config.largest_radius())  # m
        self.scale = SIZE / self.view_height  # pixels per m
        self.grounds = config.scene().grounds
        self.pygame = _pygame() if mode == "human" else None
        self.window: Any = None  # pygame's, made at the first human frame
        self.clock: Any = None

    def render(self, batch: BallBatch, e: int) -> NDArray[np.uint8] | None:
        """The frame of env ``e`` (``rgb_array``), or None after showing it (``human``)."""
        frame = self.frame(batch, e)
        if self.mode != "human":
            return frame
        self._show(frame)
        return None

    def frame(self, batch: BallBatch, e: int) -> NDArray[np.uint8]:
        """Env ``e`` of ``batch`` drawn as a (480, 480, 3) uint8 array."""
        task = batch.task
        x = batch.state.x[e]
        centre_x = float(x[:, 0].mean())
        view = View(SIZE, SIZE, self.scale, centre_x - 0.5 * SIZE / self.scale, -0.05 * self.view_height)
        canvas = Canvas(view, self.style)
        for g in self.grounds:
            canvas.ground(g.angle, g.height, g.x)
        canvas.level(task.ground_height + task.target[e])
        if task.mode == MODE_PADDLE:
            canvas.paddle(task.paddle_height[e], task.paddle_reach, task.impulse[e] > 0.0)
        canvas.ring(x, 0)
        canvas.forces(x, batch.state.contact_force[e])
        canvas.text(self._labels(batch, e), size=FONT_SIZE, spacing=LINE_SPACING)
        return canvas.array()

    @staticmethod
    def _labels(batch: BallBatch, e: int) -> list[str]:
        task = batch.task
        pressure = ring_pressure(env_model(batch.model, e), 0, batch.state.x[e])
        return [
            f"t = {task.steps[e] * task.control_dt:5.2f} s",
            f"p = {pressure / 1e3:6.1f} kPa (gas {task.setpoint[e] / 1e3:4.1f} kPa at rest)",
            f"target {task.target[e]:.2f} m, last apex {task.apex_height[e]:.2f} m",
        ]

    def _show(self, frame: NDArray[np.uint8]) -> None:
        pg = self.pygame
        assert pg is not None  # human mode
        if self.window is None:
            pg.display.init()
            self.window = pg.display.set_mode((SIZE, SIZE))
            pg.display.set_caption("InflatedBall-v3")
            self.clock = pg.time.Clock()
        pg.event.pump()
        self.window.blit(pg.image.frombuffer(frame.tobytes(), (SIZE, SIZE), "RGB"), (0, 0))
        pg.display.flip()
        self.clock.tick(self.fps)

    def close(self) -> None:
        if self.window is not None and self.pygame is not None:
            self.pygame.display.quit()
            self.window = None


def scripted(mode: str, **env_kwargs: Any) -> tuple[gym.Env[Any, Any], PressurePump | PaddleDribble]:
    """InflatedBall-v3 (``action_mode=mode``, ``rgb_array`` frames) and its scripted controller
    (the pump or the dribble): ``(env, controller)``."""
    import gymnasium as gym

    from .controllers import PaddleDribble, PressurePump
    from .envs.inflated_ball import ball_env
    from .physics.ring import total_mass

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
    from .video import write_video

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
    """``python -m ballenv.render [--out PATH] [--video PATH --mode MODE --seconds S]``: write the
    frame strip (default ``out/env.png``, outside the tracked files; the README's picture is
    ``--out docs/env.png``), or with ``--video`` a real-time clip (.mp4 or .gif)."""
    import argparse

    parser = argparse.ArgumentParser(
        prog="python -m ballenv.render", description="Write a frame strip or a clip of InflatedBall-v3."
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
