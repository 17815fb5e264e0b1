"""Drums around or under a shell (``Scene.drums``): infinitely long circular cylinders of radius
``R`` (m) about the line through ``c`` (m) along the unit axis ``a``, their record and their contact
barrier.

A point ``x`` is at the distance ``rho = |p|`` (m) from the axis, ``p = (I - a a^T)(x - c)``, in the
radial direction ``e = p / rho``; its distance from the drum's surface is (m)::

    d = s (R - rho),        grad d = -s e,        Hess d = -s (I - a a^T - e e^T) / rho

with ``s = +1`` for a drum the shells stay inside and ``s = -1`` outside. A vertex is held off the
surface by the grounds' barrier (ground.py, the same ``kappa`` N/m and ``dhat`` m)::

    B(d) = kappa dhat^2 beta(d^2 / dhat^2),      B' = 2 kappa d beta'(y),
    B'' = kappa (4 y beta''(y) + 2 beta'(y)),    y = d^2 / dhat^2,

    grad B = B' grad d,      Hess B = B'' e e^T + c P,      c = -s B' / rho,   P = I - a a^T - e e^T

(J, N, N/m). ``B'' >= 0`` and ``B' <= 0``: inside a drum ``c >= 0`` and ``Hess B`` is positive
semi-definite; outside one (a convex obstacle) ``c <= 0`` and the curvature term ``c P`` is negative
semi-definite. Newton's matrix takes its positive part (``project``): ``c P`` is dropped where
``c < 0``, which, ``e e^T`` and ``P`` being orthogonal projectors, is the exact projection of
``Hess B`` onto the positive semi-definite matrices. The normal force is ``lambda = -B' >= 0``
(N), along ``grad d``.

A straight motion ``x + alpha dx`` keeps ``d >= (1 - CCD_SAFETY) d(x)`` for ``alpha <= max_step``:
``rho(alpha)^2 = |p + alpha q|^2`` (``q = (I - a a^T) dx``) is a quadratic in ``alpha``, and the
first ``alpha > 0`` at which ``rho`` reaches ``R - (1 - CCD_SAFETY) d`` (inside) or
``R + (1 - CCD_SAFETY) d`` (outside) is its root, in closed form: exact, not a bound.
"""

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
from numpy.typing import NDArray

from ...physics.base.jit import kernel
from ...physics.walls.self_barrier import beta, beta_curvature, beta_slope
from .ground import CCD_SAFETY

if TYPE_CHECKING:
    from ..scene import Drum

F64 = NDArray[np.float64]


class Drums(NamedTuple):
    """A shell's drums: their geometry and friction (shared by the shells of a scene), the angle each
    turns over the step being tried, and the shell's lagged normal forces and scratch."""

    centre: F64  # (D, 3) m
    axis: F64  # (D, 3) unit
    radius: F64  # (D,) m
    side: F64  # (D,) s: +1 inside, -1 outside
    mu: F64  # (D,) friction coefficients
    turn: F64  # (D,) rad: the angle each drum turns over the step (turning.py)
    lam: F64  # (V, D) N: the normal forces at the step's start, held through it (lagged)
    lam_new: F64  # (V, D) N: the normal forces at the last iterate
    scratch: F64  # (3, 3): the radial direction, the surface's slide and the slip


def make_drums(drums: Sequence["Drum"], n_vertices: int, shared: Drums | None = None) -> Drums:
    """The record of ``drums`` for a shell of ``n_vertices``; the geometry, friction and ``turn``
    arrays those of ``shared`` (another shell's record) if given."""
    if shared is None:
        centre = np.array([d.centre for d in drums], dtype=np.float64).reshape(-1, 3)
        axis = np.array([d.axis for d in drums], dtype=np.float64).reshape(-1, 3)
        radius = np.array([d.radius for d in drums], dtype=np.float64)
        side = np.array([1.0 if d.inside else -1.0 for d in drums], dtype=np.float64)
        mu = np.array([d.friction for d in drums], dtype=np.float64)
        empty = np.zeros((0, 0))
        shared = Drums(centre, axis, radius, side, mu, np.zeros(len(drums)), empty, empty, empty)
    lam = np.zeros((n_vertices, len(shared.radius)))
    return shared._replace(lam=lam, lam_new=lam.copy(), scratch=np.zeros((3, 3)))


@kernel(inline="always")
def perpendicular(v, i, drums, k, origin):
    """The part of ``v[i] - origin * c_k`` (``origin`` 1.0 or 0.0) normal to drum k's axis (3 floats)."""
    r0 = v[i, 0] - origin * drums.centre[k, 0]
    r1 = v[i, 1] - origin * drums.centre[k, 1]
    r2 = v[i, 2] - origin * drums.centre[k, 2]
    a = drums.axis
    along = r0 * a[k, 0] + r1 * a[k, 1] + r2 * a[k, 2]
    return r0 - along * a[k, 0], r1 - along * a[k, 1], r2 - along * a[k, 2]


@kernel(inline="always")
def gap(x, i, drums, k):
    """``(d, rho)`` (m) of vertex i from drum k (module doc)."""
    p0, p1, p2 = perpendicular(x, i, drums, k, 1.0)
    rho = math.sqrt(p0 * p0 + p1 * p1 + p2 * p2)
    return drums.side[k] * (drums.radius[k] - rho), rho


@kernel
def barrier_energy(x, drums, dhat, kappa):
    """``sum_i sum_k B(d_ik)`` (J); inf if a vertex is at or beyond a drum's surface."""
    total = 0.0
    for k in range(drums.radius.shape[0]):
        for i in range(x.shape[0]):
            d = gap(x, i, drums, k)[0]
            if d < dhat:
                total += kappa * dhat * dhat * beta(d * d / (dhat * dhat)) if d > 0.0 else math.inf
    return total


@kernel
def add_barrier(x, drums, dhat, kappa, grad, blocks, project):
    """Adds ``grad B`` (N) to ``grad`` (V, 3) and ``Hess B`` (N/m) to ``blocks`` (V, 3, 3), its
    positive part if ``project`` (module doc); returns the number of vertex-drum pairs within ``dhat``."""
    touching = 0
    e = drums.scratch[0]
    for k in range(drums.radius.shape[0]):
        s, a = drums.side[k], drums.axis
        for i in range(x.shape[0]):
            d, rho = gap(x, i, drums, k)
            if not 0.0 < d < dhat:
                continue
            e[0], e[1], e[2] = perpendicular(x, i, drums, k, 1.0)
            for c in range(3):
                e[c] /= rho
            y = d * d / (dhat * dhat)
            slope = 2.0 * kappa * d * beta_slope(y)
            second = kappa * (4.0 * y * beta_curvature(y) + 2.0 * beta_slope(y))
            curvature = -s * slope / rho
            if project and curvature < 0.0:
                curvature = 0.0
            for c in range(3):
                grad[i, c] -= s * slope * e[c]
                for b in range(3):
                    p = (1.0 if b == c else 0.0) - a[k, c] * a[k, b] - e[c] * e[b]
                    blocks[i, c, b] += second * e[c] * e[b] + curvature * p
            touching += 1
    return touching


@kernel
def normal_forces(x, drums, dhat, kappa, out):
    """``out[i, k]`` = the normal force ``lambda`` (N) of drum k on vertex i (0 beyond ``dhat``)."""
    for k in range(drums.radius.shape[0]):
        for i in range(x.shape[0]):
            d = gap(x, i, drums, k)[0]
            out[i, k] = -2.0 * kappa * d * beta_slope(d * d / (dhat * dhat)) if 0.0 < d < dhat else 0.0


@kernel
def min_distance(x, drums):
    """The smallest distance (m) of a vertex from a drum's surface (inf without drums)."""
    low = math.inf
    for k in range(drums.radius.shape[0]):
        for i in range(x.shape[0]):
            low = min(low, gap(x, i, drums, k)[0])
    return low


@kernel(inline="always")
def _first_reach(pp, pq, qq, limit, inside):
    """The first ``alpha > 0`` at which ``|p + alpha q|^2 = pp + 2 alpha pq + alpha^2 qq`` reaches
    ``limit^2`` from the allowed side (below it inside, above it outside); inf if never."""
    c = pp - limit * limit
    disc = pq * pq - qq * c
    if inside:  # c < 0: one positive root
        if qq <= 0.0:
            return math.inf
        root = math.sqrt(max(disc, 0.0))
        return (root - pq) / qq if pq <= 0.0 else -c / (pq + root)
    if pq >= 0.0 or disc < 0.0:  # c > 0: moving away, or passing by
        return math.inf
    return c / (math.sqrt(disc) - pq)


@kernel
def max_step(x, dx, drums):
    """The largest ``alpha <= 1`` for which ``x + alpha dx`` keeps every vertex at least
    ``1 - CCD_SAFETY`` of its distance from every drum's surface (module doc)."""
    alpha = 1.0
    for k in range(drums.radius.shape[0]):
        inside = drums.side[k] > 0.0
        for i in range(x.shape[0]):
            p0, p1, p2 = perpendicular(x, i, drums, k, 1.0)
            q0, q1, q2 = perpendicular(dx, i, drums, k, 0.0)
            pp = p0 * p0 + p1 * p1 + p2 * p2
            d = drums.side[k] * (drums.radius[k] - math.sqrt(pp))
            limit = drums.radius[k] - drums.side[k] * (1.0 - CCD_SAFETY) * d
            reach = _first_reach(pp, p0 * q0 + p1 * q1 + p2 * q2, q0 * q0 + q1 * q1 + q2 * q2, limit, inside)
            alpha = min(alpha, reach)
    return alpha
