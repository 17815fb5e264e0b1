"""Drawing an env's ball to an RGB array (:mod:`ballenv.draw`, Pillow) or a pygame window.

The renderer only reads state: the ring's nodes, its ground reactions, the gas pressure, the
target and the paddle. The view follows the ball horizontally and spans the arena's lower part.
``rgb_array`` frames need Pillow only; the ``human`` window shows the same frames with pygame-ce.
Frame strips and clips of an env under its scripted controller: :mod:`ballenv.clips`.
"""

from __future__ import annotations

from types import ModuleType
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from ..draw import STYLE, Canvas, Style, View
from ..extras import optional_module
from ..physics.effects.gas import ring_pressure
from .batch import BallBatch, env_model
from .task import MODE_PADDLE

if TYPE_CHECKING:
    from .config import BallEnvConfig

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
            # the last flight apex (the start height before the first): the task's apex_height is
            # the apex of the last control step only, 0 at every step without one
            f"target {task.target[e]:.2f} m, last apex {task.last_apex[e]:.2f} m",
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
