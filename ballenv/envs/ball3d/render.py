"""Drawing an InflatedBall3D env's ball to an RGB array (:mod:`ballenv.draw3d`, NumPy only) or a
pygame window.

The renderer only reads state: the ball's vertices, its gas pressure (the ball's colour, blue at
the low end of the pressure range, red at the high end), the ground, the target spot (paddle mode)
and the paddle hovering over the ball, facing the way of its last strike. The camera follows the
ball's centre with a lag of ``FOLLOW`` s. ``rgb_array`` frames need nothing optional; the ``human``
window shows the same frames with pygame-ce.
"""

from __future__ import annotations

from types import ModuleType
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from ... import draw3d
from ...extras import optional_module

if TYPE_CHECKING:
    from .ball import Ball
    from .config import Ball3DConfig

WIDTH, HEIGHT = 480, 360  # pixels
FOLLOW = 0.3  # s, the camera's lag behind the ball's centre


def _pygame() -> ModuleType:
    return optional_module("pygame", "the human render mode", "render", "pygame-ce")


class Ball3DRenderer:
    """Draws an env's :class:`~ballenv.envs.ball3d.ball.Ball`: ``mode="rgb_array"`` returns a
    (360, 480, 3) uint8 array; ``mode="human"`` shows it in a pygame window paced to ``fps``."""

    def __init__(self, config: Ball3DConfig, mode: str, fps: float) -> None:
        self.config, self.mode, self.fps = config, mode, fps
        reach = config.target_height_range[1] + 2.0 * config.radius
        self.camera = draw3d.Camera(
            target=(0.0, 0.0, 0.5 * reach),
            elevation=0.2,
            distance=1.5 * reach + 0.4,
            width=WIDTH,
            height=HEIGHT,
        )
        low, high = config.pressure_range
        self.pressure_range = (min(low, config.initial_pressure), max(high, config.initial_pressure))
        self.time = 0.0  # s, of the last frame
        self.pygame = _pygame() if mode == "human" else None
        self.window: Any = None
        self.clock: Any = None

    def render(self, ball: Ball) -> NDArray[np.uint8] | None:
        """The frame (``rgb_array``), or None after showing it (``human``)."""
        frame = self.frame(ball)
        if self.mode != "human":
            return frame
        self._show(frame)
        return None

    def frame(self, ball: Ball) -> NDArray[np.uint8]:
        """The ball now, drawn as a (360, 480, 3) uint8 array."""
        sim, c = ball._sim(), self.config
        x = sim.x[0]
        centre = x.mean(axis=0)
        t = ball.steps * c.control_dt  # s: the camera chases the ball over the time since its last frame
        aim = (centre[0], centre[1], self.camera.target[2])
        # a new episode (time went back) is aimed at at once
        self.camera = (
            self.camera.following(aim, t - self.time, FOLLOW) if t >= self.time else self.camera.aimed_at(aim)
        )
        self.time = t
        spots, paddles = [], []
        if c.paddle:
            spots.append(draw3d.Spot((ball.spot[0], ball.spot[1], 0.0), radius=0.1, width=0.02))
            normal = -ball.impulse if np.any(ball.impulse) else np.array([0.0, 0.0, 1.0])
            top = (centre[0], centre[1], ball.target + ball.radius)
            paddles.append(draw3d.Paddle(top, tuple(normal), radius=0.1))
        return draw3d.draw(
            self.camera,
            x[None],
            sim.run.steps[0].problem.model.triangles,
            ball.scene.grounds,
            values=np.array([sim.gauge_pressure(0)]),
            value_range=self.pressure_range,
            spots=spots,
            paddles=paddles,
        )

    def _show(self, frame: NDArray[np.uint8]) -> None:
        pg = self.pygame
        assert pg is not None  # human mode
        if self.window is None:
            pg.display.init()
            self.window = pg.display.set_mode((WIDTH, HEIGHT))
            pg.display.set_caption("InflatedBall3D-v0")
            self.clock = pg.time.Clock()
        pg.event.pump()
        self.window.blit(pg.image.frombuffer(frame.tobytes(), (WIDTH, HEIGHT), "RGB"), (0, 0))
        pg.display.flip()
        self.clock.tick(self.fps)

    def close(self) -> None:
        if self.window is not None and self.pygame is not None:
            self.pygame.display.quit()
            self.window = None
