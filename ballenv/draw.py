"""One drawing path for every picture of ballenv: rings, grounds (floors, slopes, walls, ceilings),
ground reactions, the paddle, the target line and text, rasterised with Pillow into an (H, W, 3)
uint8 RGB array.

The env's frames (:mod:`ballenv.envs.render`), the scenes' videos (:mod:`ballenv.scenes.animate`) and
the docs' pictures are drawn on a :class:`Canvas`; the replay viewer's page (:mod:`ballenv.viewer`)
draws in the browser with the colours and line widths of :data:`STYLE` (``STYLE.as_json()``).
Positions in the plane are in m (y up), on the canvas in pixels (y down).
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from types import ModuleType
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .extras import optional_module

RGB = tuple[int, int, int]  # a colour, each channel 0-255


def pillow() -> tuple[ModuleType, ModuleType, ModuleType]:
    """Pillow's ``Image``, ``ImageDraw`` and ``ImageFont``; without Pillow, an ImportError naming the
    extra to install."""
    names = ("Image", "ImageDraw", "ImageFont")
    image, draw, font = (optional_module(f"PIL.{name}", "drawing", "render", "pillow") for name in names)
    return image, draw, font


@dataclass(frozen=True)
class Style:
    """Colours (RGB, 0-255), line widths (pixels) and scales shared by every picture."""

    background: RGB = (250, 250, 247)
    ground: RGB = (150, 150, 150)  # the solid side of a ground half-plane
    # ring k has colour rings[k % 4]
    rings: tuple[RGB, ...] = ((200, 60, 40), (40, 90, 200), (40, 150, 70), (150, 60, 160))
    force: RGB = (30, 110, 200)  # ground reaction arrows
    target: RGB = (40, 150, 70)  # the env's target apex (dashed)
    paddle: RGB = (60, 60, 160)
    text: RGB = (20, 20, 20)
    line_width: int = 2  # px: ring centrelines, force arrows, the target line
    paddle_width: int = 3  # px; twice that while the paddle strikes
    reach_alpha: int = 40  # 0-255: opacity of the shading of the paddle's reach
    dash: tuple[int, int] = (8, 16)  # px: dash length and period of the target line
    force_scale: float = 0.002  # m of arrow per N of ground reaction

    def ring(self, k: int) -> RGB:
        """Colour of ring ``k``."""
        return self.rings[k % len(self.rings)]

    def as_json(self) -> dict[str, Any]:
        """The style with colours as CSS hex strings (``"#c83c28"``), for the viewer's page."""

        def css(value: Any) -> Any:
            if isinstance(value, tuple) and value and isinstance(value[0], tuple):
                return [css(v) for v in value]
            if isinstance(value, tuple) and len(value) == 3:
                return "#{:02x}{:02x}{:02x}".format(*value)
            return list(value) if isinstance(value, tuple) else value

        return {f.name: css(getattr(self, f.name)) for f in dataclasses.fields(self)}


STYLE = Style()


@dataclass(frozen=True)
class View:
    """A window on the plane: ``width`` x ``height`` pixels, ``scale`` pixels per m, its
    bottom-left corner at (``x0``, ``y0``) m."""

    width: int
    height: int
    scale: float
    x0: float
    y0: float

    @classmethod
    def centred(
        cls, width: int, height: int, scale: float, centre: Sequence[float] | NDArray[np.float64]
    ) -> View:
        """The view of ``width`` x ``height`` pixels at ``scale`` px/m centred on ``centre`` (m)."""
        return cls(width, height, scale, centre[0] - 0.5 * width / scale, centre[1] - 0.5 * height / scale)

    def px(self, points: ArrayLike) -> NDArray[np.float64]:
        """Pixel coordinates (..., 2), rounded to the nearest pixel, of ``points`` (..., 2) in m."""
        p = np.asarray(points, dtype=float)
        col = (p[..., 0] - self.x0) * self.scale
        row = self.height - (p[..., 1] - self.y0) * self.scale
        return np.rint(np.stack([col, row], axis=-1))

    def centre(self) -> NDArray[np.float64]:
        """The point (m) at the middle of the view."""
        return np.array([self.x0, self.y0]) + 0.5 * np.array([self.width, self.height]) / self.scale


@functools.lru_cache(maxsize=8)
def font(size: int) -> Any:
    """Pillow's bundled font at ``size`` pixels (FreeType; the bitmap font without FreeType)."""
    _, _, ImageFont = pillow()
    return ImageFont.load_default(size)


def _xy(pixels: NDArray[np.float64]) -> list[tuple[float, ...]]:
    return [tuple(p) for p in pixels.tolist()]


class Canvas:
    """One picture being drawn: ``view`` maps metres to its pixels; :meth:`array` returns it."""

    def __init__(self, view: View, style: Style = STYLE) -> None:
        Image, ImageDraw, _ = pillow()
        self.view = view
        self.style = style
        self.image = Image.new("RGB", (view.width, view.height), style.background)
        self.draw = ImageDraw.Draw(self.image)

    def ground(self, angle: float, height: float, x: float = 0.0) -> None:
        """Fill the solid side of the ground half-plane through (``x``, ``height``) m at ``angle``
        (rad; 0 a floor, pi/2 a right wall, pi a ceiling: see :class:`ballenv.physics.Ground`)."""
        v = self.view
        far = 4.0 * (v.width + v.height) / v.scale  # m: well past every edge of the view
        n = np.array([-math.sin(angle), math.cos(angle)])  # into the free side
        d = np.array([math.cos(angle), math.sin(angle)])  # along the surface
        base = np.array([x, height])
        base = base + d * ((v.centre() - base) @ d)  # the surface's point nearest the view's centre
        corners = [base - far * d, base + far * d, base + far * d - far * n, base - far * d - far * n]
        self.draw.polygon(_xy(v.px(np.array(corners))), fill=self.style.ground)

    def ring(self, nodes: NDArray[np.float64], k: int = 0) -> None:
        """The closed centreline through ``nodes`` (n, 2) m, in ring ``k``'s colour."""
        pts = _xy(self.view.px(nodes))
        self.draw.line(pts + pts[:1], fill=self.style.ring(k), width=self.style.line_width)

    def forces(self, nodes: NDArray[np.float64], forces: NDArray[np.float64]) -> None:
        """An arrow from each node (n, 2) m along its nonzero force (n, 2) N, ``force_scale`` m/N."""
        on = np.any(forces != 0.0, axis=1)
        if not on.any():
            return
        tails = self.view.px(nodes[on])
        tips = self.view.px(nodes[on] + self.style.force_scale * forces[on])
        for a, b in zip(tails.tolist(), tips.tolist(), strict=True):
            self.draw.line([tuple(a), tuple(b)], fill=self.style.force, width=self.style.line_width)

    def level(self, y: float) -> None:
        """A dashed horizontal line across the picture at height ``y`` (m): the target apex."""
        row = float(self.view.px((0.0, y))[1])
        dash, period = self.style.dash
        for start in range(0, self.view.width, period):
            self.draw.line(
                [(start, row), (start + dash, row)], fill=self.style.target, width=self.style.line_width
            )

    def paddle(self, y: float, reach: float, striking: bool) -> None:
        """The paddle over the middle third of the picture at height ``y`` (m), its reach ``reach``
        (m) either side shaded, drawn thicker while ``striking``."""
        left, right = self.view.width // 3, 2 * self.view.width // 3
        row = float(self.view.px((0.0, y))[1])
        band = round(reach * self.view.scale)
        shade = (*self.style.paddle, self.style.reach_alpha)
        _, ImageDraw, _ = pillow()
        ImageDraw.Draw(self.image, "RGBA").rectangle(
            (left, row - band, right - 1, row + band - 1), fill=shade
        )
        width = 2 * self.style.paddle_width if striking else self.style.paddle_width
        self.draw.line([(left, row), (right, row)], fill=self.style.paddle, width=width)

    def text(
        self, lines: Sequence[str], at: tuple[int, int] = (8, 8), size: int = 10, spacing: int | None = None
    ) -> None:
        """``lines`` of text from pixel ``at`` (left, top) down, ``size`` px high, ``spacing`` px
        apart (default 1.3 x size)."""
        spacing = spacing or round(1.3 * size)
        for k, line in enumerate(lines):
            self.draw.text((at[0], at[1] + k * spacing), line, fill=self.style.text, font=font(size))

    def array(self) -> NDArray[np.uint8]:
        """The picture as a new (height, width, 3) uint8 array."""
        return np.array(self.image)
