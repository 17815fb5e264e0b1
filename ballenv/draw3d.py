"""The one renderer of the 3-D ball: shaded triangle meshes, ground planes, shadows and markers drawn
into an (H, W, 3) uint8 RGB array by pure NumPy (no OpenGL, no display, no optional package).

    camera = Camera(target=(0.0, 0.0, 0.15), distance=1.5)
    image = draw(camera, positions, triangles, grounds=scene.grounds)
    write_clip(traj, icosphere(2).triangles, "drop.mp4", fps=30)

Positions are in m with z up. The camera orbits a look-at point (:class:`Camera`) and projects in
perspective; pixel (i, j) is row i from the top, column j from the left, its centre at
(j + 0.5, i + 0.5). The balls are lit by one directional light plus ambient light (Lambert), with
per-vertex normals (Gouraud) or per-face normals (flat), hidden surfaces removed by a z-buffer. Each
ground plane n . x = height is drawn per pixel (a ray meets the plane) as a checkerboard that fades
into the sky's horizon colour with distance; the balls and paddles cast hard shadows on it along the
light. The background is a sky gradient. The same input gives the same array, bit for bit.
"""

from __future__ import annotations

import functools
import math
import os
import pathlib
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .draw import STYLE
from .video import write_video

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]
RGB = tuple[int, int, int]  # a colour, each channel 0-255
Vec3 = tuple[float, float, float]
Path = str | os.PathLike[str]

MAX_SIDE = 8192  # px: the largest image width or height
NEAR = 1e-3  # m: triangles with a corner closer to the camera's image plane than this are not drawn
COOLWARM = np.array([(59, 76, 192), (221, 221, 221), (180, 4, 38)], dtype=np.float64) / 255.0


def _fail(name: str, value: Any, valid: str) -> ValueError:
    return ValueError(f"{name} = {value!r} is out of range: must be {valid}")


def _real(name: str, value: float, low: float, high: float, valid: str) -> float:
    """``value`` as a float if it is a finite number in [low, high], else a ValueError saying ``valid``."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
        raise _fail(name, value, valid)
    if not (math.isfinite(value) and low <= value <= high):
        raise _fail(name, value, valid)
    return float(value)


def _vector3(name: str, value: ArrayLike) -> F64:
    """``value`` as a finite (3,) float array, else a ValueError naming ``name``."""
    out = np.asarray(value, dtype=np.float64)
    if out.shape != (3,) or not np.all(np.isfinite(out)):
        raise _fail(name, value, "a finite 3-vector (m)")
    return out


def _unit(v: F64) -> F64:
    return v / np.linalg.norm(v)


@dataclass(frozen=True)
class Camera:
    """A perspective camera on an orbit about a look-at point, with z up.

    target: the look-at point (m); azimuth: the angle (rad) about +z from +x to the horizontal
    direction from the target to the camera (the default -pi/2 puts the camera on -y, so +x is to
    the right); elevation: the angle (rad) of the camera above the target's horizontal plane, in
    (-1.5, 1.5); distance: from the target to the camera (m), in (0, 1e4]; fov: the vertical field of
    view (rad), in [0.01, 3]; width, height: the image's size (pixels), in [1, 8192].
    """

    target: Vec3 = (0.0, 0.0, 0.15)
    azimuth: float = -math.pi / 2
    elevation: float = 0.3
    distance: float = 1.5
    fov: float = 0.8
    width: int = 480
    height: int = 360

    def __post_init__(self) -> None:
        _vector3("Camera target", self.target)
        _real("Camera azimuth", self.azimuth, -1e6, 1e6, "a finite angle (rad)")
        _real("Camera elevation", self.elevation, -1.5, 1.5, "an angle in [-1.5, 1.5] rad")
        _real("Camera distance", self.distance, 1e-6, 1e4, "a distance in (0, 1e4] m")
        _real("Camera fov", self.fov, 0.01, 3.0, "a vertical field of view in [0.01, 3] rad")
        for name in ("width", "height"):
            value = getattr(self, name)
            if (
                isinstance(value, bool)
                or not isinstance(value, (int, np.integer))
                or not 1 <= value <= MAX_SIDE
            ):
                raise _fail(f"Camera {name}", value, f"a whole number of pixels in [1, {MAX_SIDE}]")

    @property
    def position(self) -> F64:
        """The camera's eye point (m)."""
        ce, se = math.cos(self.elevation), math.sin(self.elevation)
        offset = np.array([ce * math.cos(self.azimuth), ce * math.sin(self.azimuth), se])
        return np.asarray(self.target, dtype=np.float64) + self.distance * offset

    @property
    def focal(self) -> float:
        """The focal length in pixels: a point one unit to the side at unit depth is this far from
        the image's centre."""
        return 0.5 * self.height / math.tan(0.5 * self.fov)

    def basis(self) -> tuple[F64, F64, F64]:
        """``(right, up, forward)``: the camera's orthonormal axes in the world (forward looks at
        the target)."""
        forward = _unit(np.asarray(self.target, dtype=np.float64) - self.position)
        right = _unit(np.cross(forward, (0.0, 0.0, 1.0)))
        return right, np.cross(right, forward), forward

    def project(self, points: ArrayLike) -> tuple[F64, F64]:
        """``(pixels, depth)`` of world points (..., 3) m: pixel coordinates (..., 2) as (column, row)
        (continuous; pixel centres at half-integers) and depth along the view direction (..., ) m."""
        right, up, forward = self.basis()
        v = np.asarray(points, dtype=np.float64) - self.position
        depth = v @ forward
        with np.errstate(divide="ignore", invalid="ignore"):
            scale = self.focal / depth
        x = 0.5 * self.width + (v @ right) * scale
        y = 0.5 * self.height - (v @ up) * scale
        return np.stack([x, y], axis=-1), depth

    def aimed_at(self, point: ArrayLike) -> Camera:
        """This camera looking at ``point`` (m) from the same azimuth, elevation and distance."""
        return replace(self, target=tuple(float(c) for c in _vector3("point", point)))  # type: ignore[arg-type]

    def following(self, point: ArrayLike, dt: float, time_constant: float) -> Camera:
        """This camera after ``dt`` s of smoothly chasing ``point`` (m): the target moves the fraction
        1 - exp(-dt / time_constant) of the way (a first-order lag of ``time_constant`` s; 0 re-aims at
        once)."""
        _real("dt", dt, 0.0, 1e6, "a time step in [0, 1e6] s")
        _real("time_constant", time_constant, 0.0, 1e6, "a time in [0, 1e6] s")
        share = 1.0 if time_constant == 0.0 else -math.expm1(-dt / time_constant)
        target = np.asarray(self.target, dtype=np.float64)
        return self.aimed_at(target + share * (_vector3("point", point) - target))


@dataclass(frozen=True)
class Style3D:
    """Light, colours (RGB, 0-255) and sizes of the 3-D pictures.

    light: the direction towards the (distant) light, any non-zero 3-vector; ambient, diffuse: the
    shares of the ambient and the directional light (a surface facing the light gets their sum);
    shadow: the share of the light left on a ground in a shadow; tile: the checkerboard's square (m);
    fog: the distance (m) at which a ground has faded half way into the horizon colour; segments:
    the triangles of a paddle's disc. Shares are in [0, 1], lengths in (0, 1e6] m.
    """

    light: Vec3 = (-0.45, -0.6, 1.0)
    ambient: float = 0.35
    diffuse: float = 0.65
    shadow: float = 0.55
    balls: tuple[RGB, ...] = STYLE.rings  # ball k has colour balls[k % len(balls)]
    floor: tuple[RGB, RGB] = ((222, 219, 210), (186, 183, 175))
    tile: float = 0.2
    fog: float = 15.0
    horizon: RGB = (226, 233, 241)
    zenith: RGB = (118, 158, 212)
    spot: RGB = STYLE.target
    paddle: RGB = STYLE.paddle
    segments: int = 32

    def __post_init__(self) -> None:
        light = _vector3("Style3D light", self.light)
        if not np.linalg.norm(light) > 0.0:
            raise _fail("Style3D light", self.light, "a non-zero 3-vector")
        for name in ("ambient", "diffuse", "shadow"):
            _real(f"Style3D {name}", getattr(self, name), 0.0, 1.0, "a share in [0, 1]")
        for name in ("tile", "fog"):
            _real(f"Style3D {name}", getattr(self, name), 1e-9, 1e6, "a length in (0, 1e6] m")
        if not (isinstance(self.segments, int) and 3 <= self.segments <= 4096):
            raise _fail("Style3D segments", self.segments, "a whole number in [3, 4096]")

    def light_direction(self) -> F64:
        """The unit vector towards the light."""
        return _unit(np.asarray(self.light, dtype=np.float64))


STYLE3D = Style3D()


@dataclass(frozen=True)
class Spot:
    """A target spot on a ground: a ring of outer ``radius`` (m) and line ``width`` (m) about
    ``centre`` (m); a width of at least the radius fills it as a disc."""

    centre: Vec3
    radius: float = 0.1
    width: float = 0.02


@dataclass(frozen=True)
class Paddle:
    """A paddle: a flat disc of ``radius`` (m) about ``centre`` (m), facing along ``normal`` (any
    non-zero 3-vector)."""

    centre: Vec3
    normal: Vec3 = (0.0, 0.0, 1.0)
    radius: float = 0.08


@dataclass(frozen=True)
class Plane:
    """A ground plane n . x = height: ``normal`` n a unit 3-vector into the free side, ``height`` (m)."""

    normal: F64
    height: float


def planes(grounds: Iterable[Any]) -> list[Plane]:
    """The planes of ``grounds``: each an object with ``normal`` and ``height`` (such as a shell
    scene's ``Ground``) or a pair ``(normal, height)``; normals are normalised here."""
    out = []
    for k, ground in enumerate(grounds):
        normal, height = (ground.normal, ground.height) if hasattr(ground, "normal") else ground
        n = _vector3(f"grounds[{k}] normal", normal)
        if not np.linalg.norm(n) > 0.0:
            raise _fail(f"grounds[{k}] normal", normal, "a non-zero 3-vector")
        out.append(Plane(_unit(n), _real(f"grounds[{k}] height", height, -1e6, 1e6, "a height in m")))
    return out


def colormap(values: ArrayLike, value_range: tuple[float, float]) -> F64:
    """RGB colours (..., 3) in [0, 1] of ``values`` on a blue-grey-red scale: ``value_range`` (low,
    high) maps to blue and red, values outside it to the end colours."""
    low, high = value_range
    s = np.clip((np.asarray(values, dtype=np.float64) - low) / (high - low), 0.0, 1.0) * 2.0
    k = np.minimum(s.astype(np.int64), 1)
    f = (s - k)[..., None]
    return COOLWARM[k] * (1.0 - f) + COOLWARM[k + 1] * f


def _check_mesh(positions: ArrayLike, triangles: ArrayLike) -> tuple[F64, I64]:
    """``positions`` (S, V, 3) and ``triangles`` (T, 3) as arrays, or a ValueError naming the one
    that is wrong and what it must be."""
    x = np.asarray(positions, dtype=np.float64)
    if x.ndim != 3 or x.shape[0] < 1 or x.shape[1] < 3 or x.shape[2] != 3:
        raise _fail("positions shape", x.shape, "(S, V, 3) with S >= 1 balls and V >= 3 vertices (m)")
    if not np.all(np.isfinite(x)):
        raise _fail("positions", "non-finite values", "finite (m)")
    tri = np.asarray(triangles)
    if tri.ndim != 2 or tri.shape[1] != 3 or tri.shape[0] < 1 or tri.dtype.kind not in "iu":
        raise _fail("triangles shape", (tri.shape, str(tri.dtype)), "(T, 3) integers with T >= 1")
    if tri.min() < 0 or tri.max() >= x.shape[1]:
        raise _fail("triangles", (int(tri.min()), int(tri.max())), f"vertex indices in [0, {x.shape[1] - 1}]")
    return x, tri.astype(np.int64)


def _check_values(values: ArrayLike, value_range: tuple[float, float] | None, shape: tuple[int, int]) -> F64:
    """Per-ball (S,) or per-vertex (S, V) ``values`` as (S, V), or a ValueError."""
    v = np.asarray(values, dtype=np.float64)
    if v.shape not in (shape[:1], shape):
        raise _fail("values shape", v.shape, f"{shape[:1]} per ball or {shape} per vertex")
    if not np.all(np.isfinite(v)):
        raise _fail("values", "non-finite values", "finite")
    if value_range is None or len(value_range) != 2:
        raise _fail("value_range", value_range, "(low, high) with low < high when values are given")
    low = _real("value_range low", value_range[0], -1e300, 1e300, "finite")
    if not _real("value_range high", value_range[1], -1e300, 1e300, "finite") > low:
        raise _fail("value_range", value_range, "(low, high) with low < high")
    return np.broadcast_to(v if v.ndim == 2 else v[:, None], shape)


def _base_colours(shape: tuple[int, int], values: F64 | None, vr: Any, style: Style3D) -> F64:
    """Unlit colours (S, V, 3) in [0, 1]: the balls' own colours, or ``values`` through
    :func:`colormap`."""
    if values is not None:
        return colormap(values, vr)
    own = np.array([style.balls[k % len(style.balls)] for k in range(shape[0])], dtype=np.float64) / 255.0
    return np.broadcast_to(own[:, None, :], (*shape, 3))


def _face_normals(x: F64, tri: I64) -> F64:
    """Area-weighted normals (..., T, 3) of the triangles (twice their area long)."""
    a, b, c = x[..., tri[:, 0], :], x[..., tri[:, 1], :], x[..., tri[:, 2], :]
    return np.cross(b - a, c - a)


def _vertex_normals(x: F64, tri: I64, face: F64) -> F64:
    """Unit vertex normals (S, V, 3): the sums of the adjacent faces' area-weighted normals."""
    s, v = x.shape[:2]
    ids = (np.arange(s)[:, None, None] * v + tri[None]).reshape(-1)
    n = np.stack([np.bincount(ids, np.repeat(face[..., d], 3, axis=-1).reshape(-1), s * v) for d in range(3)])
    n = n.T.reshape(s, v, 3)
    return n / np.maximum(np.linalg.norm(n, axis=-1, keepdims=True), 1e-300)


def _lit(normals: F64, style: Style3D, two_sided: bool = False) -> F64:
    """The light share (...,) on surfaces of unit ``normals`` (..., 3): ambient + diffuse max(0, n.l)."""
    facing = normals @ style.light_direction()
    facing = np.abs(facing) if two_sided else np.maximum(facing, 0.0)
    return style.ambient + style.diffuse * facing


@dataclass
class Soup:
    """Triangles to rasterise: corners (T, 3, 3) m, corner colours (T, 3, 3) in [0, 1]."""

    corners: F64
    colours: F64

    @staticmethod
    def joined(soups: Sequence[Soup]) -> Soup:
        """One soup of all the triangles of ``soups``, in order."""
        return Soup(np.concatenate([s.corners for s in soups]), np.concatenate([s.colours for s in soups]))


def _ball_soup(x: F64, tri: I64, base: F64, camera: Camera, smooth: bool, style: Style3D) -> Soup:
    """The balls' triangles that face the camera, lit (Gouraud if ``smooth``, else flat)."""
    face = _face_normals(x, tri)
    corners = x[:, tri]  # (S, T, 3, 3)
    front = np.einsum("stk,stk->st", face, camera.position - corners[:, :, 0]) > 0.0
    if smooth:
        light = _lit(_vertex_normals(x, tri, face), style)[..., None] * base
        colours = light[:, tri]
    else:
        unit = face / np.maximum(np.linalg.norm(face, axis=-1, keepdims=True), 1e-300)
        flat = base[:, tri].mean(axis=2) * _lit(unit, style)[..., None]
        colours = np.repeat(flat[:, :, None], 3, axis=2)
    return Soup(corners[front], colours[front])


def _disc(centre: F64, normal: F64, radius: float, segments: int) -> F64:
    """A fan of ``segments`` triangles (segments, 3, 3) m making a disc."""
    e1 = _unit(np.cross(normal, (1.0, 0.0, 0.0) if abs(normal[0]) < 0.9 else (0.0, 1.0, 0.0)))
    e2 = np.cross(normal, e1)
    angle = np.linspace(0.0, 2.0 * np.pi, segments + 1)
    rim = centre + radius * (np.cos(angle)[:, None] * e1 + np.sin(angle)[:, None] * e2)
    return np.stack([np.broadcast_to(centre, (segments, 3)), rim[:-1], rim[1:]], axis=1)


def _paddle_soup(paddles: Sequence[Paddle], style: Style3D) -> Soup:
    """The paddles' discs, lit on both faces."""
    corners, colours = [np.zeros((0, 3, 3))], [np.zeros((0, 3, 3))]
    for k, p in enumerate(paddles):
        n = _vector3(f"paddles[{k}] normal", p.normal)
        if not np.linalg.norm(n) > 0.0:
            raise _fail(f"paddles[{k}] normal", p.normal, "a non-zero 3-vector")
        radius = _real(f"paddles[{k}] radius", p.radius, 1e-6, 1e3, "a radius in (0, 1e3] m")
        corners.append(_disc(_vector3(f"paddles[{k}] centre", p.centre), _unit(n), radius, style.segments))
        shade = _lit(_unit(n), style, two_sided=True) * np.asarray(style.paddle, dtype=np.float64) / 255.0
        colours.append(np.broadcast_to(shade, (style.segments, 3, 3)))
    return Soup(np.concatenate(corners), np.concatenate(colours))


def _edges(xy: F64) -> F64:
    """Coefficients (3, 3, T) of the barycentric weights as affine functions of the pixel position:
    weight k at (x, y) is ``c[k, 0] * x + c[k, 1] * y + c[k, 2]``."""
    out = np.empty((3, 3, len(xy)))
    area = (xy[:, 1, 0] - xy[:, 0, 0]) * (xy[:, 2, 1] - xy[:, 0, 1]) - (xy[:, 1, 1] - xy[:, 0, 1]) * (
        xy[:, 2, 0] - xy[:, 0, 0]
    )
    for k in range(3):
        p, q = xy[:, (k + 1) % 3], xy[:, (k + 2) % 3]  # the edge opposite corner k
        a, b = p[:, 1] - q[:, 1], q[:, 0] - p[:, 0]
        out[k] = np.stack([a, b, -(a * p[:, 0] + b * p[:, 1])]) / area
    return out


def _boxes(xy: F64, width: int, height: int) -> tuple[I64, I64, I64, I64]:
    """The first column and row and the numbers of columns and rows of the pixels whose centres are
    in each triangle's bounding box, within the image."""
    lo = np.maximum(np.ceil(xy.min(axis=1) - 0.5), 0.0)
    hi = np.minimum(np.floor(xy.max(axis=1) - 0.5), (width - 1, height - 1))
    n = np.maximum(hi - lo + 1.0, 0.0).astype(np.int64)
    lo = lo.astype(np.int64)
    return lo[:, 0], lo[:, 1], n[:, 0], n[:, 1]


def _fragments(xy: F64, width: int, height: int) -> tuple[I64, I64, F64]:
    """The pixels inside 2-D triangles ``xy`` (T, 3, 2) px: ``(triangle, pixel, weights)``, with
    ``pixel = row * width + column`` and the barycentric weights (N, 3) of the pixel's centre.
    Triangles are batched by the size of their bounding boxes so that each batch is one array."""
    e, f = xy[:, 1] - xy[:, 0], xy[:, 2] - xy[:, 0]
    area = e[:, 0] * f[:, 1] - e[:, 1] * f[:, 0]
    ok = np.all(np.isfinite(xy), axis=(1, 2)) & (np.abs(area) > 1e-12)
    ids = np.flatnonzero(ok)
    x0, y0, nx, ny = _boxes(xy[ids], width, height)
    keep = (nx > 0) & (ny > 0)
    ids, x0, y0, nx, ny = ids[keep], x0[keep], y0[keep], nx[keep], ny[keep]
    coef = _edges(xy[ids])
    level = np.ceil(np.log2(np.maximum(nx, ny))).astype(np.int64)
    out: list[tuple[I64, I64, F64]] = []
    for lv in np.unique(level):
        b = np.flatnonzero(level == lv)
        cols, rows = np.arange(nx[b].max()), np.arange(ny[b].max())
        px = (x0[b, None, None] + cols[None, None, :] + 0.5).astype(np.float64)
        py = (y0[b, None, None] + rows[None, :, None] + 0.5).astype(np.float64)
        c = coef[:, :, b, None, None]
        w = c[:, 0] * px + c[:, 1] * py + c[:, 2]  # (3, B, rows, cols)
        inside = np.all(w >= 0.0, axis=0)
        inside &= (cols[None, None, :] < nx[b, None, None]) & (rows[None, :, None] < ny[b, None, None])
        t, r, q = np.nonzero(inside)
        pixel = (y0[b][t] + r) * width + x0[b][t] + q
        out.append((ids[b][t], pixel, w[:, inside].T))
    if not out:
        return np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros((0, 3))
    return (
        np.concatenate([o[0] for o in out]),
        np.concatenate([o[1] for o in out]),
        np.concatenate([o[2] for o in out]),
    )


@dataclass
class Backdrop:
    """The image behind the meshes, per pixel (flattened, row-major): ``colour`` (P, 3) RGB uint8,
    ``inv_depth`` (P,) 1/m (0 where the sky is seen) and ``ground`` (P,) the index of the plane seen
    (-1: the sky)."""

    colour: NDArray[np.uint8]
    inv_depth: F64
    ground: NDArray[np.int16]


F32 = NDArray[np.float32]


class Rays:
    """The camera's rays through the pixel centres, ray(i, j) = forward + u[j] right + v[i] up (unit
    depth), kept as the two separable offsets so that a ray's component along any vector is an
    outer sum (H, W)."""

    def __init__(self, camera: Camera) -> None:
        self.right, self.up, self.forward = camera.basis()
        self.u = ((np.arange(camera.width) + 0.5 - 0.5 * camera.width) / camera.focal).astype(np.float32)
        self.v = ((0.5 * camera.height - np.arange(camera.height) - 0.5) / camera.focal).astype(np.float32)
        self.length = np.sqrt(1.0 + self.u[None, :] ** 2 + self.v[:, None] ** 2)  # (H, W)

    def along(self, e: ArrayLike) -> F32:
        """The rays' components (H, W) along the vector ``e``."""
        e = np.asarray(e, dtype=np.float64)
        a, b, c = (np.float32(e @ axis) for axis in (self.forward, self.right, self.up))
        return (a + self.u[None, :] * b) + self.v[:, None] * c


def _rgb(colour: RGB, scale: float = 1.0) -> F64:
    """``colour``'s channels times ``scale`` (0-255 for scale 1)."""
    return np.asarray(colour, dtype=np.float64) * scale


def _axes(normal: F64) -> tuple[F64, F64]:
    """Two unit vectors spanning the plane of ``normal``: the checkerboard's axes."""
    e1 = _unit(np.cross(normal, (1.0, 0.0, 0.0) if abs(normal[0]) < 0.9 else (0.0, 1.0, 0.0)))
    return e1, np.cross(normal, e1)


@dataclass
class PlaneView:
    """What the camera sees of one ground plane, whatever its eye's place along the plane: the
    ``weight`` (H, W) of the plane's own colour (1 - fade where the plane is seen, else 0), the
    offsets ``reach`` (3, H, W) m from the eye to the points seen, their coordinates ``q1``, ``q2``
    (H, W) in tiles along the checkerboard's axes ``e1``, ``e2``, and the colour step ``step`` (3,)
    (0-255, lit) from a light tile to a dark one, ``spot`` (3,) from a light tile to a spot."""

    weight: F32
    reach: F32
    q1: F32
    q2: F32
    e1: F64
    e2: F64
    step: F64
    spot: F64


@dataclass
class View:
    """What a camera sees of the sky and the ground planes, except the planes' patterns: ``base``
    (3, H, W), 0.5 plus the colour (0-255) with every plane's tiles light, the planes' ``PlaneView``s,
    ``inv_depth`` and ``ground`` as in :class:`Backdrop`."""

    base: F32
    planes: list[PlaneView]
    inv_depth: F64
    ground: NDArray[np.int16]


def _sky(rays: Rays, style: Style3D) -> F32:
    """The sky's colour (3, H, W) 0-255: the horizon colour blending into the zenith colour with the
    square root of the sine of the ray's elevation."""
    s = np.sqrt(np.clip(rays.along((0.0, 0.0, 1.0)) / rays.length, 0.0, 1.0))
    h, z = _rgb(style.horizon).astype(np.float32), _rgb(style.zenith).astype(np.float32)
    return h[:, None, None] + s * (z - h)[:, None, None]


def _plane_view(rays: Rays, plane: Plane, t: F32, seen: NDArray[np.bool_], style: Style3D) -> PlaneView:
    """The :class:`PlaneView` of ``plane``, met at ray parameters ``t`` where ``seen``."""
    t = np.where(seen, t, np.float32(0.0))
    distance = t * rays.length
    weight = np.where(seen, np.float32(style.fog) / (distance + np.float32(style.fog)), np.float32(0.0))
    e1, e2 = _axes(plane.normal)
    tile = np.float32(1.0 / style.tile)
    reach = np.stack([t * rays.along(np.eye(3)[c]) for c in range(3)])
    light = float(_lit(plane.normal, style))
    floor0 = _rgb(style.floor[0], light)
    return PlaneView(
        weight, reach, t * rays.along(e1) * tile, t * rays.along(e2) * tile, e1, e2,
        _rgb(style.floor[1], light) - floor0, _rgb(style.spot, light) - floor0,
    )  # fmt: skip


@functools.lru_cache(maxsize=4)
def _view(camera: Camera, grounds: tuple[tuple[Vec3, float], ...], style: Style3D) -> View:
    """The :class:`View` of ``camera`` (its orientation and image: its target and distance are unused) over
    ``grounds``, each given as (normal, the eye's height above it (m)). Cached: a camera that slides
    along the ground sees the same view, only its patterns move."""
    rays = Rays(camera)
    depth = np.full((camera.height, camera.width), np.inf, dtype=np.float32)
    ground = np.full(depth.shape, -1, dtype=np.int16)
    base, views = _sky(rays, style), []
    for k, (normal, above) in enumerate(grounds):
        plane = Plane(np.asarray(normal), 0.0)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            t = np.float32(-above) / rays.along(plane.normal)
        seen = (t > NEAR) & (t < depth) if above > 0.0 else np.zeros(depth.shape, dtype=bool)
        depth, ground = np.where(seen, t, depth), np.where(seen, np.int16(k), ground)
        views.append(_plane_view(rays, plane, t, seen, style))
        light = _rgb(style.floor[0], float(_lit(plane.normal, style)))
        own = light[:, None, None] * views[-1].weight + _rgb(style.horizon)[:, None, None] * (
            1 - views[-1].weight
        )
        base = np.where(seen, own.astype(np.float32), base)
    inv = (np.float32(1.0) / depth).astype(np.float64)  # 0 for the sky (infinite depth)
    view = View(base + np.float32(0.5), views, inv.reshape(-1), ground.reshape(-1))
    shared: list[NDArray[Any]] = [view.base, view.inv_depth, view.ground]
    for array in shared + [a for v in views for a in (v.weight, v.reach, v.q1, v.q2)]:
        array.flags.writeable = False  # shared by every frame of this view
    return view


def _ring(spots: Sequence[Spot], reach: F32, eye: F64) -> F32:
    """1 where the points ``eye + reach`` are on one of the ``spots``' rings, else 0."""
    out = np.zeros(reach.shape[1:], dtype=bool)
    for k, spot in enumerate(spots):
        radius = _real(f"spots[{k}] radius", spot.radius, 1e-6, 1e3, "a radius in (0, 1e3] m")
        width = _real(f"spots[{k}] width", spot.width, 1e-6, 1e3, "a line width in (0, 1e3] m")
        d = (eye - _vector3(f"spots[{k}] centre", spot.centre)).astype(np.float32)
        r2 = (d[0] + reach[0]) ** 2 + (d[1] + reach[1]) ** 2 + (d[2] + reach[2]) ** 2
        out |= (r2 <= radius**2) & (r2 >= max(radius - width, 0.0) ** 2)
    return out.astype(np.float32)


def _backdrop(camera: Camera, grounds: Sequence[Plane], spots: Sequence[Spot], style: Style3D) -> Backdrop:
    """The sky and the ground planes as the camera sees them: each pixel shows the nearest plane its
    ray meets in front of the camera (checkered, spots on it, fading into the horizon colour with
    distance, half at ``style.fog``), else the sky."""
    eye = camera.position
    key = tuple((tuple(float(c) for c in g.normal), float(g.normal @ eye - g.height)) for g in grounds)
    view = _view(replace(camera, target=(0.0, 0.0, 0.0), distance=1.0), key, style)
    colour = list(view.base)
    for pv in view.planes:
        a = np.floor(pv.q1 + np.float32(eye @ pv.e1 / style.tile))
        b = np.floor(pv.q2 + np.float32(eye @ pv.e2 / style.tile))
        dark = ((a + b).astype(np.int32) & 1).astype(np.float32) * pv.weight
        ring = _ring(spots, pv.reach, eye) if spots else None
        for c in range(3):
            colour[c] = colour[c] + dark * np.float32(pv.step[c])
            if ring is not None:  # a spot's colour instead of the tile's
                colour[c] += ring * (pv.weight * np.float32(pv.spot[c]) - dark * np.float32(pv.step[c]))
    rgb = np.stack([c.astype(np.uint8) for c in colour], axis=-1).reshape(-1, 3)
    return Backdrop(rgb, view.inv_depth, view.ground)


def _shadow(back: Backdrop, casters: F64, grounds: Sequence[Plane], camera: Camera, style: Style3D) -> None:
    """Darken, in place, the ground pixels in the shadow of the triangles ``casters`` (T, 3, 3) m:
    the triangles projected along the light onto each plane and rasterised there."""
    light = style.light_direction()
    for k, plane in enumerate(grounds):
        towards = plane.normal @ light
        if towards <= 1e-6 or len(casters) == 0:
            continue
        above = np.maximum(casters @ plane.normal - plane.height, 0.0)
        xy, depth = camera.project(casters - above[..., None] * (light / towards))
        xy = xy[np.all(depth > NEAR, axis=1)]
        _, pixel, _ = _fragments(xy, camera.width, camera.height)
        dark = np.zeros(len(back.ground), dtype=bool)
        dark[pixel] = True
        dark &= back.ground == k
        back.colour[dark] = np.rint(back.colour[dark] * style.shadow).astype(np.uint8)


def _paint(back: Backdrop, soup: Soup, camera: Camera) -> NDArray[np.uint8]:
    """The backdrop's colours (P, 3) uint8 with the triangles of ``soup`` drawn over it where they are
    nearer than it and than each other (a z-buffer of 1 / depth, larger is nearer)."""
    xy, depth = camera.project(soup.corners)
    front = np.all(depth > NEAR, axis=1)
    xy, inv, col = xy[front], 1.0 / depth[front], soup.colours[front]
    tri, pixel, w = _fragments(xy, camera.width, camera.height)
    z = np.einsum("nk,nk->n", w, inv[tri])
    zbuf = back.inv_depth.copy()
    np.maximum.at(zbuf, pixel, z)
    win = np.flatnonzero(z >= zbuf[pixel])
    owner = np.full(len(zbuf), -1, dtype=np.int64)
    owner[pixel[win]] = win  # equal depths: the later fragment, the same every time
    seen = np.flatnonzero(owner >= 0)
    f = owner[seen]
    colour = back.colour.copy()
    shaded = np.einsum("nk,nkc->nc", w[f], col[tri[f]])
    colour[seen] = np.rint(np.clip(shaded, 0.0, 1.0) * 255.0).astype(np.uint8)
    return colour


def draw(
    camera: Camera,
    positions: ArrayLike,
    triangles: ArrayLike,
    grounds: Iterable[Any] = (),
    *,
    values: ArrayLike | None = None,
    value_range: tuple[float, float] | None = None,
    spots: Sequence[Spot] = (),
    paddles: Sequence[Paddle] = (),
    smooth: bool = True,
    style: Style3D = STYLE3D,
) -> NDArray[np.uint8]:
    """The picture (H, W, 3) uint8 of balls over ground planes, as ``camera`` sees it.

    positions: vertex positions (S, V, 3) m of S balls sharing the mesh ``triangles`` (T, 3) (vertex
    indices, outward oriented); grounds: planes n . x = height (:func:`planes`); values: a scalar
    per ball (S,) or per vertex (S, V) (such as gauge pressure in Pa) coloured through
    :func:`colormap` over ``value_range`` (low, high), else each ball has its style colour; spots:
    target rings on the grounds; paddles: discs; smooth: Gouraud (per-vertex normals) or flat
    (per-face normals) shading. Balls and paddles cast shadows on the grounds along the light.
    """
    x, tri = _check_mesh(positions, triangles)
    vals = None if values is None else _check_values(values, value_range, x.shape[:2])
    ground_planes = planes(grounds)
    back = _backdrop(camera, ground_planes, spots, style)
    balls = _ball_soup(x, tri, _base_colours(x.shape[:2], vals, value_range, style), camera, smooth, style)
    pads = _paddle_soup(paddles, style)
    lit_faces = _face_normals(x, tri) @ style.light_direction() > 0.0
    _shadow(back, np.concatenate([x[:, tri][lit_faces], pads.corners]), ground_planes, camera, style)
    return _paint(back, Soup.joined([balls, pads]), camera).reshape(camera.height, camera.width, 3)


def frame_times(t: ArrayLike, fps: float) -> F64:
    """The times (s) of a clip at ``fps`` frames per second over the sample times ``t`` (s): from
    t[0] every 1 / fps s up to t[-1], so that the clip plays in real time."""
    t = np.asarray(t, dtype=np.float64)
    if t.ndim != 1 or len(t) < 1 or not np.all(np.isfinite(t)) or np.any(np.diff(t) < 0.0):
        raise _fail("t", f"array of shape {t.shape}", "finite, non-decreasing sample times (T,) s, T >= 1")
    rate = _real("fps", fps, 1e-3, 1e4, "a frame rate in [1e-3, 1e4] frames per second")
    count = int(np.floor((t[-1] - t[0]) * rate + 1e-9)) + 1
    return t[0] + np.arange(count) / rate


def resample(t: ArrayLike, samples: ArrayLike, times: ArrayLike) -> F64:
    """``samples`` (T, ...) taken at times ``t`` (T,) s, linearly interpolated at ``times`` (N,) s
    (held at the ends): (N, ...)."""
    t, y, s = (np.asarray(a, dtype=np.float64) for a in (t, samples, times))
    hi = np.clip(np.searchsorted(t, s, side="right"), 1, max(len(t) - 1, 1))
    lo = hi - 1 if len(t) > 1 else hi * 0
    span = t[hi] - t[lo] if len(t) > 1 else np.ones_like(s)
    f = np.clip(np.divide(s - t[lo], span, out=np.zeros_like(s), where=span > 0), 0.0, 1.0)
    f = f.reshape(-1, *([1] * (y.ndim - 1)))
    return y[lo] * (1.0 - f) + y[hi if len(t) > 1 else lo] * f


def clip_frames(
    traj: Any,
    triangles: ArrayLike,
    fps: float = 30.0,
    camera: Camera | None = None,
    follow: float | None = 0.3,
    pressure_range: tuple[float, float] | None = None,
    colour_by_pressure: bool = True,
    spots: Sequence[Spot] = (),
    style: Style3D = STYLE3D,
) -> Iterator[NDArray[np.uint8]]:
    """The frames (H, W, 3) uint8 of a shell trajectory ``traj`` (its ``t`` (T,) s, ``x`` (T, S, V, 3)
    m, ``pressure`` (T, S) Pa and ``scene.grounds``, drawn where they are at t = 0) at ``fps`` frames
    per second of simulated time (:func:`frame_times`, positions interpolated linearly).

    The camera's target follows the balls' centroid horizontally with the lag ``follow`` (s; None:
    the camera stays put, 0: re-aimed every frame). With ``colour_by_pressure`` each ball is coloured
    by its gauge pressure over ``pressure_range`` (low, high) Pa, by default the trajectory's range.
    """
    camera = Camera() if camera is None else camera
    times = frame_times(traj.t, fps)
    x_all = resample(traj.t, traj.x, times)
    p_all = resample(traj.t, traj.pressure, times)
    if colour_by_pressure and pressure_range is None:
        low, high = float(np.min(traj.pressure)), float(np.max(traj.pressure))
        pressure_range = (low, high) if high > low else (low - 1.0, high + 1.0)
    grounds = planes(traj.scene.grounds)
    height = camera.target[2]
    for k, x in enumerate(x_all):
        centre = np.append(x.reshape(-1, 3).mean(axis=0)[:2], height)
        if k == 0 and follow is not None:
            camera = camera.aimed_at(centre)
        elif follow is not None:
            camera = camera.following(centre, 1.0 / fps, follow)
        values = p_all[k] if colour_by_pressure else None
        yield draw(
            camera, x, triangles, grounds, values=values, value_range=pressure_range, spots=spots, style=style
        )


def write_clip(
    traj: Any, triangles: ArrayLike, path: Path, fps: float = 30.0, **options: Any
) -> pathlib.Path:
    """Write the frames of :func:`clip_frames` (``options`` are its keywords) as a video at ``fps``
    frames per second (MP4 or GIF by the suffix of ``path``), so that it plays in real time. Returns
    the path."""
    return write_video(clip_frames(traj, triangles, fps, **options), path, fps)
