"""Grounds (half-planes and drums): constrained nodes, reactions and Coulomb friction inside the
Newton system.

A ground ``g`` is the half-plane ``n_g . x >= d_g(t)`` with unit normal ``n_g = (-sin a, cos a)`` for
a slope angle ``a`` (rad) and ``d_g(0) = n_g . (x_g, height)``: the surface passes through the
ground's point ``(Ground.x, Ground.height)`` at t = 0 and moves with the velocity ``w_g(t)``
(:mod:`ballenv.physics.ground.motion`; ``d = d0``, ``w = 0`` for a fixed ground). A drum (``Scene.drums``) is
the set ``phi(x) = s (|x - c| - R) >= 0`` (``s = -1``: the rings inside, ``+1``: outside) with the normal
``n(x) = s (x - c) / |x - c|`` and the surface velocity ``w(x) = Omega e_z x (x - c)`` at the node
(:func:`frame`, :func:`surface_velocity`); for a half-plane ``phi = n . x - d``. The kernels here
read the grounds at one time, rows ``base.layout.SURFACE`` (``Workspace.surface``: the step's end time
t1), and evaluate a drum's normal at the node's end position ``x1``.
A node in contact is constrained on the surface and keeps the size of the system (Baraff & Witkin's
filtered, mass-modified formulation written for the step's displacement): its two residual rows
(``r_i = M inertia_i - F_i``, N) become

    tangential:  t . r_i + mu N_i s(v_t)   = 0     (Coulomb friction, N_i = n . r_i the reaction)
    normal:      c_M m phi(x1_i, t1) = 0         (the node ends the step on the surface)

with ``t = (-n_y, n_x)``, the slip ``v_t = t . (v_i - w)`` relative to the surface and the regularised
sign ``s(v) = v / sqrt(v^2 + eps^2)`` (``eps`` = ``Scene.friction_regularization``, m/s). The Jacobian
rows are the same combinations of the unconstrained rows (exact, including ``dN_i/dx = n . J_i`` and
``mu N s'(v_t) dv_t/dx``), so the band structure and the low-rank Woodbury terms survive. On a
drum ``n``, ``t`` and ``w`` also depend on the node's own position, which adds to the tangential
row's own 2x2 block (the circle's curvature ``kappa = s / |x - c|``; :func:`drum_row_terms`)

    d(t . r)/dx  += -kappa N t^T,          d(mu N s)/dx += mu s kappa (t . r) t^T + mu N s' dv_t/dx,
    dv_t/dx       = c_v t^T - Omega n^T - kappa (n . (v - w)) t^T,

from ``dn/dx = kappa t t^T``, ``dt/dx = -kappa n t^T`` and ``dw/dx = Omega [[0, -1], [1, 0]]``.
A constraint whose reaction ``N_i`` pulls is released; a free node below a ground is constrained;
a constrained node ends the step with the surface's normal velocity (:func:`rest_on_grounds`).
"""

import math
from typing import TYPE_CHECKING

from ..base.jit import kernel
from ..base.layout import (
    GROUND_PLANE,
    SURFACE_CENTRE,
    SURFACE_FRICTION,
    SURFACE_KIND,
    SURFACE_NORMAL,
    SURFACE_NORMAL_ACCELERATION,
    SURFACE_OFFSET,
    SURFACE_RADIUS,
    SURFACE_SPIN,
    SURFACE_VELOCITY,
)
from ..base.linalg import BAND_HALF_WIDTH

if TYPE_CHECKING:
    from ..scene import Scene

FREE = -1
PENETRATION_TOLERANCE = -1e-12  # m: a free node deeper than this below a ground gets constrained


@kernel
def frame(grounds, g, x, y):
    """Ground ``g``'s unit normal ``(nx, ny)`` into its free side at the point ``(x, y)`` (m) and the
    point's signed distance ``phi`` (m, positive on the free side): a half-plane's fixed ``n`` and
    ``n . x - d``; a drum's ``n = s (x - c) / |x - c|`` and ``phi = s (|x - c| - R)`` (``s`` its
    kind: -1 inside, +1 outside; at the centre itself, ``n = (0, -s)``). ``grounds``: rows
    ``base.layout.GROUND`` or ``base.layout.SURFACE`` (their first eight columns agree)."""
    side = grounds[g, SURFACE_KIND]
    if side == GROUND_PLANE:
        nx, ny = grounds[g, SURFACE_NORMAL], grounds[g, SURFACE_NORMAL + 1]
        return nx, ny, nx * x + ny * y - grounds[g, SURFACE_OFFSET]
    rx = x - grounds[g, SURFACE_CENTRE]
    ry = y - grounds[g, SURFACE_CENTRE + 1]
    dist = math.sqrt(rx * rx + ry * ry)
    phi = side * (dist - grounds[g, SURFACE_RADIUS])
    if dist == 0.0:
        return 0.0, -side, phi
    return side * rx / dist, side * ry / dist, phi


@kernel
def surface_velocity(grounds, g, x, y):
    """Velocity ``w`` (m/s) of ground ``g``'s surface at the point ``(x, y)`` (m): a half-plane's
    ``w(t)``, a drum's ``Omega (-(y - c_y), x - c_x)`` (``grounds``: rows ``base.layout.SURFACE``)."""
    if grounds[g, SURFACE_KIND] == GROUND_PLANE:
        return grounds[g, SURFACE_VELOCITY], grounds[g, SURFACE_VELOCITY + 1]
    spin = grounds[g, SURFACE_SPIN]
    return -spin * (y - grounds[g, SURFACE_CENTRE + 1]), spin * (x - grounds[g, SURFACE_CENTRE])


@kernel
def deepest_ground(grounds, x, y):
    """(ground index, signed distance in m) of the ground the point is deepest below (or nearest)."""
    best = 0
    best_phi = math.inf
    for g in range(grounds.shape[0]):
        _, _, phi = frame(grounds, g, x, y)
        if phi < best_phi:
            best_phi = phi
            best = g
    return best, best_phi


@kernel(inline="always")
def slip(grounds, g, x1, ve, i, tx, ty):
    """Node ``i``'s velocity ``ve[i]`` relative to ground ``g``'s surface at its position ``x1[i]``
    along the tangent ``(tx, ty)`` (m/s): ``t . (v - w)``."""
    wx, wy = surface_velocity(grounds, g, x1[i, 0], x1[i, 1])
    return tx * (ve[i, 0] - wx) + ty * (ve[i, 1] - wy)


@kernel
def constrain_residual(grounds, active, x1, ve, res, node_mass, c_mass, eps, reaction, friction, tangential):
    """Replace the rows of active nodes (see module doc; ``grounds``: rows ``base.layout.SURFACE`` at the
    step's end); store their normal reaction N_i (N) in ``reaction``, the friction force along t
    (N) in ``friction`` and the unconstrained tangential row ``t . r_i`` (N) in ``tangential`` (a
    drum's Jacobian uses it)."""
    n = active.shape[0]
    for i in range(n):
        g = active[i]
        if g == FREE:
            reaction[i] = 0.0
            friction[i] = 0.0
            continue
        nx, ny, phi = frame(grounds, g, x1[i, 0], x1[i, 1])
        mu = grounds[g, SURFACE_FRICTION]
        tx, ty = -ny, nx
        rx, ry = res[2 * i], res[2 * i + 1]
        rn = nx * rx + ny * ry
        rt = tx * rx + ty * ry
        s = 0.0
        if mu > 0.0:
            vt = slip(grounds, g, x1, ve, i, tx, ty)
            s = vt / math.sqrt(vt * vt + eps * eps)
        reaction[i] = rn
        friction[i] = -mu * rn * s
        tangential[i] = rt
        row_t = rt + mu * rn * s
        row_n = c_mass * node_mass * phi
        if abs(nx) > abs(ny):
            res[2 * i], res[2 * i + 1] = row_n, row_t
        else:
            res[2 * i], res[2 * i + 1] = row_t, row_n


@kernel(inline="always")
def sliding(grounds, g, x1, ve, i, eps):
    """Ground ``g``'s normal ``(nx, ny)`` at node ``i``'s position ``x1[i]``, tangent
    ``(tx, ty) = (-ny, nx)`` and friction ``mu``, and the regularised sliding direction
    ``s = vt / sqrt(vt^2 + eps^2)`` of node ``i``'s velocity ``ve[i]`` relative to the surface
    (``vt`` along t, m/s: :func:`slip`) with its derivative ``ds/dvt`` (s/m); ``s = ds = 0``
    without friction."""
    nx, ny, _ = frame(grounds, g, x1[i, 0], x1[i, 1])
    mu = grounds[g, SURFACE_FRICTION]
    tx, ty = -ny, nx
    s = 0.0
    ds = 0.0
    if mu > 0.0:
        vt = slip(grounds, g, x1, ve, i, tx, ty)
        q = vt * vt + eps * eps
        s = vt / math.sqrt(q)
        ds = eps * eps / (q * math.sqrt(q))
    return nx, ny, tx, ty, mu, s, ds


@kernel
def drum_row_terms(grounds, g, x1, ve, i, rn, rt, mu, s, ds):
    """The terms (row vector, N/m) a drum adds to the derivative of node ``i``'s tangential row
    ``t . r_i + mu N_i s(v_t)`` by its own position ``x1[i]``, beyond the row combination of the
    unconstrained rows: the turning of ``n`` and ``t`` along the circle (curvature
    ``kappa = s / |x - c|``, 1/m) and the surface velocity's change with the point (module doc).
    ``rn``, ``rt``: the unconstrained rows ``n . r_i``, ``t . r_i`` (N)."""
    rx = x1[i, 0] - grounds[g, SURFACE_CENTRE]
    ry = x1[i, 1] - grounds[g, SURFACE_CENTRE + 1]
    dist = math.sqrt(rx * rx + ry * ry)
    if dist == 0.0:
        return 0.0, 0.0
    side = grounds[g, SURFACE_KIND]
    kappa = side / dist
    nx, ny = side * rx / dist, side * ry / dist
    tx, ty = -ny, nx
    spin = grounds[g, SURFACE_SPIN]
    vn = nx * (ve[i, 0] + spin * ry) + ny * (ve[i, 1] - spin * rx)
    along_t = kappa * (mu * s * rt - rn) - mu * rn * ds * kappa * vn
    along_n = -mu * rn * ds * spin
    return along_t * tx + along_n * nx, along_t * ty + along_n * ny


@kernel
def constrain_jacobian(
    grounds, active, x1, ve, reaction, tangential, band, pos, u, rank, node_mass, c_mass, c_v, eps
):
    """Apply the row combinations of :func:`constrain_residual` to the band and to the rows of the
    low-rank factor ``u`` (natural order), and a drum's own-position terms (:func:`drum_row_terms`;
    ``tangential``: the unconstrained tangential rows :func:`constrain_residual` kept)."""
    w = BAND_HALF_WIDTH
    n = active.shape[0]
    for i in range(n):
        g = active[i]
        if g == FREE:
            continue
        nx, ny, tx, ty, mu, s, ds = sliding(grounds, g, x1, ve, i, eps)
        ax = tx + mu * s * nx
        ay = ty + mu * s * ny
        p = 2 * pos[i]
        swap = abs(nx) > abs(ny)
        row_t = p + 1 if swap else p
        row_n = p if swap else p + 1
        # columns of node blocks within 4 positions: DOFs p - 8 .. p + 9
        lo = max(0, p - 2 * 4)
        hi = min(band.shape[0] - 1, p + 2 * 4 + 1)
        new_t = 0.0
        for c in range(lo, hi + 1):
            vx = band[p, w + c - p]
            vy = band[p + 1, w + c - p - 1]
            new_t = ax * vx + ay * vy
            band[row_t, w + c - row_t] = new_t
            band[row_n, w + c - row_n] = 0.0
        extra = mu * reaction[i] * ds * c_v
        band[row_t, w + p - row_t] += extra * tx
        band[row_t, w + p + 1 - row_t] += extra * ty
        band[row_n, w + p - row_n] = c_mass * node_mass * nx
        band[row_n, w + p + 1 - row_n] = c_mass * node_mass * ny
        if grounds[g, SURFACE_KIND] != GROUND_PLANE:
            kx, ky = drum_row_terms(grounds, g, x1, ve, i, reaction[i], tangential[i], mu, s, ds)
            band[row_t, w + p - row_t] += kx
            band[row_t, w + p + 1 - row_t] += ky
    constrain_low_rank_rows(grounds, active, x1, ve, u, 0, rank, eps)


@kernel
def constrain_low_rank_rows(grounds, active, x1, ve, u, first, last, eps):
    """Apply the row combinations of :func:`constrain_residual` to columns ``first .. last - 1``
    of a low-rank factor ``u`` (natural order): the effects' columns in :func:`constrain_jacobian`,
    the self-contact barrier's in the Newton step."""
    for i in range(active.shape[0]):
        g = active[i]
        if g == FREE:
            continue
        nx, ny, tx, ty, mu, s, _ = sliding(grounds, g, x1, ve, i, eps)
        ax = tx + mu * s * nx
        ay = ty + mu * s * ny
        swap = abs(nx) > abs(ny)
        for k in range(first, last):
            ut = ax * u[2 * i, k] + ay * u[2 * i + 1, k]
            u[2 * i, k] = 0.0 if swap else ut
            u[2 * i + 1, k] = ut if swap else 0.0


@kernel
def activate_penetrating(grounds, active, x1, only_deeper_than):
    """Constrain free nodes below a ground; returns True if any was added."""
    changed = False
    for i in range(active.shape[0]):
        if active[i] == FREE:
            g, phi = deepest_ground(grounds, x1[i, 0], x1[i, 1])
            if phi < only_deeper_than:
                active[i] = g
                changed = True
    return changed


@kernel
def rest_on_grounds(grounds, active, x1, v1, a1):
    """A constrained node ends the step at rest on the surface in the ground's normal direction: its
    normal velocity and algorithmic acceleration become the surface's, ``n . w`` and ``a_n``
    (``grounds``: rows ``base.layout.SURFACE`` at the step's end; 0 for a fixed ground). On a drum (normal
    at the node's position ``x1[i]``) ``n . w = 0`` and ``a_n = -kappa v_t^2`` (m/s^2), the normal
    acceleration of a point moving along the circle at the speed ``v_t = t . v`` (curvature
    ``kappa = s / |x - c|``: towards the centre inside a drum). Without this,
    backward Euler's ``v1 = (x1 - x0) / h`` leaves a node that arrived from a gap a velocity into
    the ground, and the Newmark update of generalized-alpha reflects it and leaves an acceleration
    spike that the alpha_m term feeds back into the next steps (the known weakness of Newmark
    schemes with contact).

    Returns ``sum_i (w_n - v_n,i) w_n`` (m^2/s^2): times the node mass, the work the surface does
    through the impulses of this velocity change, ``m (w_n - v_n) n . w`` (0 on a fixed ground)."""
    work = 0.0
    for i in range(active.shape[0]):
        g = active[i]
        if g == FREE:
            continue
        if grounds[g, SURFACE_KIND] != GROUND_PLANE:
            rest_on_drum(grounds, g, x1, v1, a1, i)
            continue
        nx, ny = grounds[g, SURFACE_NORMAL], grounds[g, SURFACE_NORMAL + 1]
        wn = grounds[g, SURFACE_VELOCITY] * nx + grounds[g, SURFACE_VELOCITY + 1] * ny
        vn = v1[i, 0] * nx + v1[i, 1] * ny - wn
        an = a1[i, 0] * nx + a1[i, 1] * ny - grounds[g, SURFACE_NORMAL_ACCELERATION]
        v1[i, 0] -= vn * nx
        v1[i, 1] -= vn * ny
        a1[i, 0] -= an * nx
        a1[i, 1] -= an * ny
        work -= vn * wn
    return work


@kernel
def rest_on_drum(grounds, g, x1, v1, a1, i):
    """:func:`rest_on_grounds` for node ``i`` on drum ``g``: no normal velocity (a turning drum's
    surface moves along itself, so the velocity change does no work) and the normal acceleration
    of motion along the circle."""
    rx = x1[i, 0] - grounds[g, SURFACE_CENTRE]
    ry = x1[i, 1] - grounds[g, SURFACE_CENTRE + 1]
    dist = math.sqrt(rx * rx + ry * ry)
    if dist == 0.0:
        return
    nx, ny, _ = frame(grounds, g, x1[i, 0], x1[i, 1])
    vn = v1[i, 0] * nx + v1[i, 1] * ny
    v1[i, 0] -= vn * nx
    v1[i, 1] -= vn * ny
    vt = -ny * v1[i, 0] + nx * v1[i, 1]
    an = a1[i, 0] * nx + a1[i, 1] * ny + grounds[g, SURFACE_KIND] / dist * vt * vt
    a1[i, 0] -= an * nx
    a1[i, 1] -= an * ny


def ground_enabled(scene: "Scene") -> bool:
    """The scene has grounds or drums: contact is on."""
    return bool(scene.grounds or scene.drums)


def friction_enabled(scene: "Scene") -> bool:
    """A ground or a drum has friction."""
    return any(g.friction > 0.0 for g in scene.grounds) or any(d.friction > 0.0 for d in scene.drums)
