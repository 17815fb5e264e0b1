"""The contact vertices' own descent within a step's Newton iteration (implicit.py): each vertex
that touches a ground moves, the others held, to the minimiser of its part of ``Phi``.

A vertex pressed on a ground carries the stiffest and least smooth terms of the incremental
potential: the barrier ``B`` (ground.py), steep near the ground, and the lagged friction ``D``
(friction.py), whose stiffness below the smoothing slip ``e = eps_v h`` is ``2 mu lambda / e``
(N/m): on the default ball pressed by tens of newtons at sub-millisecond steps, about a thousand
times the vertex's mass term ``c_M m_i``. A Newton correction of the whole skin
that moves such a vertex across ``e`` (about a micrometre) finds a friction force its quadratic model
did not expect, and the line search cuts the whole correction for that one vertex (the
measurements: docs/notes/benchmarks.md, "The contact vertices' own descent").

So before each Newton correction after the first, each contact vertex ``i`` descends on its own
model (N, m; ``delta`` its move, the others fixed)::

    q_i(delta) = g_i . delta + delta^T H_i delta / 2 + C_i(x_i + delta) - C_i(x_i)

with ``C_i`` the vertex's barriers and friction (exact), ``g_i`` the rest of ``grad Phi`` at ``x_i``
and ``H_i`` the rest of its diagonal 3 x 3 block of Newton's matrix (the skin's block as last
loaded, the mass term, the low-rank terms' part; stepsolve.py). ``q_i`` is convex: Newton's
method on three unknowns, each move cut short of the grounds and halved until ``q_i`` drops
(Armijo), stopping when ``|grad q_i|`` is below ``LOCAL_TOL`` of the force Newton's test asks of the
vertex. ``H_i`` models the skin, so the moves are kept only if ``Phi`` itself dropped
(implicit.newton): the iteration still converges to the same solution, by the same test.
"""

import math

from ...physics.base.jit import kernel
from ..rest.equilibrium import ARMIJO, HALVINGS
from ..touch import friction, ground

LOCAL_ITER = 20  # Newton iterations of a vertex's own descent
LOCAL_TOL = 0.1  # its residual (N) against the force Newton's test asks of the vertex


@kernel
def touches(st, sp, x, i):
    """True if vertex ``i`` is within ``dhat`` of a ground or has a lagged friction force."""
    for g in range(st.normals.shape[0]):
        d = ground.distance(x, i, st.normals, st.heights, g)
        if d < st.dhat or (st.mu[g] > 0.0 and sp.lam[i, g] > 0.0):
            return True
    return False


@kernel
def vertex_contact(st, sp, x, i, e, grad, hess, u):
    """``C_i`` (J) at ``x[i]``: vertex ``i``'s barriers and friction (smoothing slip ``e`` m), their
    gradient (N) into ``grad`` (1, 3) and Hessian (N/m) into ``hess`` (1, 3, 3); inf at or below a
    ground. ``u`` (3,) scratch."""
    grad[:] = 0.0
    hess[:] = 0.0
    dhat, total = st.dhat, 0.0
    for g in range(st.normals.shape[0]):
        n = st.normals[g]
        d = ground.distance(x, i, st.normals, st.heights, g)
        if d <= 0.0:
            return math.inf
        if d < dhat:
            total += ground.barrier(d, dhat, st.kappa)
            slope, curvature = ground.barrier_derivatives(d, dhat, st.kappa)
            for a in range(3):
                grad[0, a] += slope * n[a]
                for b in range(3):
                    hess[0, a, b] += curvature * n[a] * n[b]
        w = st.mu[g] * sp.lam[i, g]
        if w > 0.0:
            y = friction.slip(x, sp.x0, st.normals, st.slide, i, g, u)
            total += w * friction.smoothed(y, e)
            friction.add_vertex(grad, hess, 0, w, y, e, u, n)
    return total


@kernel
def smooth_block(op, mass_term, i, out):
    """``H_i`` (module doc) into ``out`` (3, 3) N/m, from the operator as last loaded."""
    k = op.pattern.diagonal_slot[i]
    for a in range(3):
        for b in range(3):
            out[a, b] = op.values[k, a, b] + (mass_term[i] if a == b else 0.0)
            for j in range(op.weights.shape[0]):
                out[a, b] += op.weights[j] * op.vectors[j, i, a] * op.vectors[j, i, b]


@kernel
def _model(gs, h, t0, t1, t2):
    """``g . t + t^T H t / 2`` (J) for ``t = (t0, t1, t2)`` (m)."""
    t = (t0, t1, t2)
    out = 0.0
    for a in range(3):
        out += gs[a] * t[a]
        for b in range(3):
            out += 0.5 * t[a] * h[a, b] * t[b]
    return out


@kernel
def _newton_move(h, hc, gq):
    """``(True, p)`` with ``p = -(H + Hc)^-1 gq`` (m) by cofactors (``hc`` (1, 3, 3)), or
    ``(False, 0)`` when ``H + Hc`` is not positive definite."""
    m00, m01, m02 = h[0, 0] + hc[0, 0, 0], h[0, 1] + hc[0, 0, 1], h[0, 2] + hc[0, 0, 2]
    m11, m12, m22 = h[1, 1] + hc[0, 1, 1], h[1, 2] + hc[0, 1, 2], h[2, 2] + hc[0, 2, 2]
    c00, c01, c02 = m11 * m22 - m12 * m12, m12 * m02 - m01 * m22, m01 * m12 - m11 * m02
    det = m00 * c00 + m01 * c01 + m02 * c02
    if not (m00 > 0.0 and m00 * m11 - m01 * m01 > 0.0 and det > 0.0):
        return False, 0.0, 0.0, 0.0
    c11, c12, c22 = m00 * m22 - m02 * m02, m01 * m02 - m00 * m12, m00 * m11 - m01 * m01
    p0 = -(c00 * gq[0] + c01 * gq[1] + c02 * gq[2]) / det
    p1 = -(c01 * gq[0] + c11 * gq[1] + c12 * gq[2]) / det
    p2 = -(c02 * gq[0] + c12 * gq[1] + c22 * gq[2]) / det
    return True, p0, p1, p2


@kernel
def _max_step(st, x, i, p0, p1, p2):
    """The largest ``alpha <= 1`` keeping vertex ``i`` at ``1 - CCD_SAFETY`` of its distance from
    every ground along ``(p0, p1, p2)`` (ground.max_step for one vertex)."""
    alpha = 1.0
    for g in range(st.normals.shape[0]):
        n = st.normals[g]
        rate = n[0] * p0 + n[1] * p1 + n[2] * p2
        if rate < 0.0:
            alpha = min(alpha, ground.CCD_SAFETY * ground.distance(x, i, st.normals, st.heights, g) / -rate)
    return alpha


@kernel
def relax_vertex(st, sp, wk, i, e, tolerance):
    """Vertex ``i``'s own descent (module doc) on ``wk.x`` from the gradient ``wk.grad`` at it, to a
    residual of ``tolerance`` (N); returns True if it moved."""
    x, h, gc, hc, u = wk.x, wk.vertex_block, wk.vertex_grad, wk.vertex_hess, wk.u3
    smooth_block(st.op, wk.mass_term, i, h)
    c = vertex_contact(st, sp, x, i, e, gc, hc, u)
    if not math.isfinite(c):
        return False
    gs0, gs1, gs2 = wk.grad[i, 0] - gc[0, 0], wk.grad[i, 1] - gc[0, 1], wk.grad[i, 2] - gc[0, 2]
    o0, o1, o2 = x[i, 0], x[i, 1], x[i, 2]
    d0 = d1 = d2 = 0.0  # the move so far (m)
    q = c  # q_i + C_i(x_i) (J)
    moved = False
    for _ in range(LOCAL_ITER):
        gq = (
            gs0 + h[0, 0] * d0 + h[0, 1] * d1 + h[0, 2] * d2 + gc[0, 0],
            gs1 + h[1, 0] * d0 + h[1, 1] * d1 + h[1, 2] * d2 + gc[0, 1],
            gs2 + h[2, 0] * d0 + h[2, 1] * d1 + h[2, 2] * d2 + gc[0, 2],
        )
        if max(abs(gq[0]), abs(gq[1]), abs(gq[2])) <= tolerance:
            break
        ok, p0, p1, p2 = _newton_move(h, hc, gq)
        if not ok:
            break
        slope = gq[0] * p0 + gq[1] * p1 + gq[2] * p2
        alpha = _max_step(st, x, i, p0, p1, p2)
        accepted = False
        for _ in range(HALVINGS):
            t0, t1, t2 = d0 + alpha * p0, d1 + alpha * p1, d2 + alpha * p2
            x[i, 0], x[i, 1], x[i, 2] = o0 + t0, o1 + t1, o2 + t2
            qn = _model((gs0, gs1, gs2), h, t0, t1, t2) + vertex_contact(st, sp, x, i, e, gc, hc, u)
            if qn <= q + ARMIJO * alpha * slope:
                d0, d1, d2, q, accepted, moved = t0, t1, t2, qn, True, True
                break
            alpha *= 0.5
        if not accepted:
            x[i, 0], x[i, 1], x[i, 2] = o0 + d0, o1 + d1, o2 + d2
            break
    return moved


@kernel
def relax(st, sp, wk, goal):
    """Every contact vertex's own descent (module doc) on ``wk.x``, each to ``LOCAL_TOL`` of the
    force Newton's test ``goal`` (m/s^2) asks of it; returns the number of vertices moved."""
    e = st.slip_speed * sp.coef[0]
    mass = st.problem.model.mass
    moved = 0
    for i in range(wk.x.shape[0]):
        if touches(st, sp, wk.x, i):
            moved += relax_vertex(st, sp, wk, i, e, LOCAL_TOL * goal * mass[i])
    return moved
