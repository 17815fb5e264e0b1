"""Drawing an env's ball to an RGB array or a pygame window (pygame-ce, the ``render`` extra).

The renderer only reads state: the ring's nodes, its ground reactions, the gas pressure, the
target and the paddle. The view follows the ball horizontally and spans the arena's lower part.
"""

import numpy as np

from .envs.batch import MODE_PADDLE, env_model
from .physics.effects.gas import ring_pressure

SIZE = 480  # pixels, square
BACKGROUND = (250, 250, 247)
GROUND = (90, 90, 90)
RING = (200, 60, 40)
FORCE = (30, 110, 200)
TARGET = (40, 150, 70)
PADDLE = (60, 60, 160)
TEXT = (20, 20, 20)
FORCE_SCALE = 0.002  # m of arrow per N


def _pygame():
    try:
        import pygame
    except ImportError as err:  # pragma: no cover - depends on the installed extras
        raise ImportError(
            "rendering needs pygame-ce: pip install 'ballenv[render]' (or pip install pygame-ce)"
        ) from err
    return pygame


class BallRenderer:
    """Draws env ``e`` of a :class:`~ballenv.envs.batch.BallBatch`.

    ``mode="rgb_array"`` draws off screen and returns a (H, W, 3) uint8 array without opening a
    window; ``mode="human"`` shows a window and paces it to ``fps``.
    """

    def __init__(self, config, mode, fps):
        self.config = config
        self.mode = mode
        self.fps = fps
        self.view_height = max(1.5, config.target_height_range[1] + 4.0 * config.largest_radius())
        self.scale = SIZE / self.view_height  # pixels per m
        self.pygame = _pygame()
        self.window = None
        self.clock = None
        self.font = None

    def render(self, batch, e):
        pg = self.pygame
        if self.mode == "human" and self.window is None:
            pg.display.init()
            self.window = pg.display.set_mode((SIZE, SIZE))
            pg.display.set_caption("InflatedBall-v1")
            self.clock = pg.time.Clock()
        if self.font is None:
            pg.font.init()
            self.font = pg.font.Font(None, 20)
        surface = pg.Surface((SIZE, SIZE))
        self._draw(surface, batch, e)
        if self.mode == "human":
            pg.event.pump()
            self.window.blit(surface, (0, 0))
            pg.display.flip()
            self.clock.tick(self.fps)
            return None
        return np.transpose(np.array(pg.surfarray.pixels3d(surface)), axes=(1, 0, 2)).copy()

    def _draw(self, surface, batch, e):
        pg = self.pygame
        task = batch.task
        x = batch.state.x[e]
        centre_x = float(x[:, 0].mean())

        def px(p):
            return (
                int(round(SIZE / 2 + (p[0] - centre_x) * self.scale)),
                int(round(SIZE - (p[1] + 0.05 * self.view_height) * self.scale)),
            )

        surface.fill(BACKGROUND)
        ground_y = px((centre_x, task.ground_height))[1]
        pg.draw.rect(surface, GROUND, (0, ground_y, SIZE, SIZE - ground_y))
        target_y = px((centre_x, task.ground_height + task.target[e]))[1]
        for start in range(0, SIZE, 16):
            pg.draw.line(surface, TARGET, (start, target_y), (start + 8, target_y), 2)
        if task.mode == MODE_PADDLE:
            top = px((centre_x, task.paddle_height[e]))[1]
            band = int(round(task.paddle_reach * self.scale))
            shade = pg.Surface((SIZE // 3, 2 * band), pg.SRCALPHA)
            shade.fill((*PADDLE, 40))
            surface.blit(shade, (SIZE // 3, top - band))
            width = 6 if task.impulse[e] > 0.0 else 3
            pg.draw.line(surface, PADDLE, (SIZE // 3, top), (2 * SIZE // 3, top), width)
        points = [px(p) for p in x]
        pg.draw.polygon(surface, RING, points, 2)
        force = batch.state.contact_force[e]
        for p, f in zip(x, force, strict=True):
            if f[0] != 0.0 or f[1] != 0.0:
                tip = (p[0] + FORCE_SCALE * f[0], p[1] + FORCE_SCALE * f[1])
                pg.draw.line(surface, FORCE, px(p), px(tip), 2)
        pressure = ring_pressure(env_model(batch.model, e), 0, x)
        lines = [
            f"t = {task.steps[e] * task.control_dt:5.2f} s",
            f"p = {pressure / 1e3:6.1f} kPa (gas {task.setpoint[e] / 1e3:4.1f} kPa at rest)",
            f"target {task.target[e]:.2f} m, last apex {task.apex_height[e]:.2f} m",
        ]
        for k, line in enumerate(lines):
            surface.blit(self.font.render(line, True, TEXT), (8, 8 + 18 * k))

    def close(self):
        if self.window is not None:
            self.pygame.display.quit()
            self.window = None


def frame_strip(out, steps=(0, 30, 36, 42, 90), seed=3):
    """Write a PNG strip of frames of both action modes under their scripted controllers."""
    import gymnasium as gym

    from .controllers import PaddleDribble, PressurePump
    from .physics.ring import total_mass

    rows = []
    for mode in ("pressure", "paddle"):
        env = gym.make("InflatedBall-v1", action_mode=mode, render_mode="rgb_array")
        obs, _ = env.reset(seed=seed)
        config = env.unwrapped.config
        structure = env.unwrapped.observation_structure
        if mode == "pressure":
            controller = PressurePump(structure)
        else:
            mass = total_mass(config.ring(config.initial_pressure))
            controller = PaddleDribble(structure, mass, max_impulse=config.paddle_max_impulse)
        frames = []
        for k in range(max(steps) + 1):
            if k in steps:
                frames.append(env.render())
            obs, *_ = env.step(controller.act(obs))
        rows.append(np.concatenate(frames, axis=1))
        env.close()
    image = np.concatenate(rows, axis=0)
    pg = _pygame()
    pg.image.save(pg.surfarray.make_surface(np.transpose(image, (1, 0, 2))), str(out))
    return out


def main(argv=None):
    """``python -m ballenv.render [--out PATH]``: write the frame strip (default ``out/env.png``,
    outside the tracked files; the README's picture is ``--out docs/env.png``)."""
    import argparse
    import os
    import pathlib

    os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
    parser = argparse.ArgumentParser(description="Write a frame strip of InflatedBall-v1 (both modes).")
    parser.add_argument("--out", default="out/env.png", help="PNG file to write (default out/env.png)")
    out = pathlib.Path(parser.parse_args(argv).out)
    out.parent.mkdir(parents=True, exist_ok=True)
    print(frame_strip(out))


if __name__ == "__main__":
    main()
