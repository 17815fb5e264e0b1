"""Bending of a shell: the discrete-shell hinge energy (Grinspun et al. 2003) with its exact
gradient and Hessian.

A hinge ``(x0, x1, x2, x3)`` is the edge ``x0 x1`` between the triangles ``(x0, x1, x2)`` and
``(x0, x3, x1)`` (both oriented outwards, mesh.py). With ``a = x1 - x0``, ``b = x2 - x0``,
``c = x3 - x0`` the triangles' normals are ``n1 = a x b`` and ``n2 = c x a``, and::

    X = n1 . n2 = (a.b)(a.c) - (a.a)(b.c),   Y = (n1 x n2) . a / |a| = -|a| det(a, b, c)

so that ``X = |n1| |n2| cos(theta)``, ``Y = |n1| |n2| sin(theta)``: the dihedral angle
``theta = atan2(Y, X)`` (rad) is the turn of the normal across the edge, positive where the surface
bends away from its outward normal (a sphere's hinges). ``X`` and ``Y`` are polynomials of
``a, b, c`` (with ``|a|``), so their exact gradients and Hessians are short, and::

    dtheta = (X dY - Y dX) / r^2,   r^2 = X^2 + Y^2,
    d2theta = [X d2Y - Y d2X + dX dY^T - dY dX^T] / r^2 - dtheta (2 X dX + 2 Y dY)^T / r^2.

(the same derivatives as Tamstorf and Grinspun 2013, written through X and Y). The energy of a hinge
with rest angle ``theta0``, rest edge length ``l`` and rest triangle areas ``A1, A2`` is::

    W = k_b / 2  l^2 / (A1 + A2)  (theta - theta0)^2,   k_b = E h^3 / (12 (1 - nu^2))  (N m)

that is ``k_b / 6`` times Grinspun's weight ``3 l^2 / (A1 + A2)``. On a lattice of equilateral
triangles bent into any quadratic surface of curvature change ``dK`` (a 2 x 2 tensor, 1/m), the
hinges' energy per area is exactly::

    k_b / 2 [ tr(dK)^2 - (8/3) det(dK) ]

against Kirchhoff-Love's ``k_b / 2 [ tr(dK)^2 - 2 (1 - nu) det(dK) ]``: the mean-curvature term,
which alone sets the bending operator ``k_b nabla^4 w`` (point loads, dimples, bending waves), is
exact; the Gaussian term is that of ``nu = -1/3`` (it changes the energy of a uniform change of
curvature, such as a sphere's breathing, and nothing in the bulk of a shallow deformation).
"""

import numpy as np

from ...physics.base.jit import kernel


def rest_hinges(vertices, hinges):
    """Rest angles theta0 (H,) (rad) and weights ``l^2 / (2 (A1 + A2))`` (H,) of a rest mesh's hinges
    (the energy of a hinge is ``k_b weight (theta - theta0)^2``)."""
    x0, x1, x2, x3 = (vertices[hinges[:, m]] for m in range(4))
    a, b, c = x1 - x0, x2 - x0, x3 - x0
    n1, n2 = np.cross(a, b), np.cross(c, a)
    big_x = np.einsum("ij,ij->i", n1, n2)
    big_y = -np.linalg.norm(a, axis=1) * np.einsum("ij,ij->i", a, np.cross(b, c))
    areas = 0.5 * (np.linalg.norm(n1, axis=1) + np.linalg.norm(n2, axis=1))
    return np.arctan2(big_y, big_x), np.einsum("ij,ij->i", a, a) / (2.0 * areas)


@kernel(inline="always")
def _edge_vectors(x, hinge, k, abc):
    """``abc`` (3, 3) = rows a, b, c of hinge ``k``."""
    for m in range(3):
        for d in range(3):
            abc[m, d] = x[hinge[k, m + 1], d] - x[hinge[k, 0], d]


@kernel(inline="always")
def _angle(abc):
    """``(theta, X, Y, |a|, det)`` of the hinge with rows a, b, c in ``abc``."""
    a, b, c = abc[0], abc[1], abc[2]
    ab = a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    ac = a[0] * c[0] + a[1] * c[1] + a[2] * c[2]
    aa = a[0] * a[0] + a[1] * a[1] + a[2] * a[2]
    bc = b[0] * c[0] + b[1] * c[1] + b[2] * c[2]
    det = (
        a[0] * (b[1] * c[2] - b[2] * c[1])
        + a[1] * (b[2] * c[0] - b[0] * c[2])
        + a[2] * (b[0] * c[1] - b[1] * c[0])
    )
    la = np.sqrt(aa)
    big_x = ab * ac - aa * bc
    big_y = -la * det
    return np.arctan2(big_y, big_x), big_x, big_y, la, det


@kernel(inline="always")
def _cross_row(u, v, out, row):
    out[row, 0] = u[1] * v[2] - u[2] * v[1]
    out[row, 1] = u[2] * v[0] - u[0] * v[2]
    out[row, 2] = u[0] * v[1] - u[1] * v[0]


@kernel
def _first_derivatives(abc, la, det, dx, dy, cr):
    """Gradients of X and Y with respect to (a, b, c) into ``dx``, ``dy`` (9,); ``cr`` (3, 3)
    scratch: rows b x c, c x a, a x b (the gradient of det)."""
    a, b, c = abc[0], abc[1], abc[2]
    _cross_row(b, c, cr, 0)
    _cross_row(c, a, cr, 1)
    _cross_row(a, b, cr, 2)
    ab = a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    ac = a[0] * c[0] + a[1] * c[1] + a[2] * c[2]
    aa = a[0] * a[0] + a[1] * a[1] + a[2] * a[2]
    bc = b[0] * c[0] + b[1] * c[1] + b[2] * c[2]
    for d in range(3):
        dx[d] = b[d] * ac + c[d] * ab - 2.0 * a[d] * bc
        dx[3 + d] = a[d] * ac - c[d] * aa
        dx[6 + d] = a[d] * ab - b[d] * aa
        dy[d] = -(a[d] / la * det + la * cr[0, d])
        dy[3 + d] = -la * cr[1, d]
        dy[6 + d] = -la * cr[2, d]


@kernel(inline="always")
def _skew(v, i, j):
    """Entry (i, j) of the cross-product matrix [v]x (``[v]x w = v x w``)."""
    if i == j:
        return 0.0
    k = 3 - i - j
    sign = 1.0 if (j - i) % 3 == 1 else -1.0  # (0,1), (1,2), (2,0): -v_k; (1,0), (2,1), (0,2): +v_k
    return -sign * v[k]


@kernel
def _second_derivatives(abc, la, det, cr, hx, hy):
    """Hessians of X and Y with respect to (a, b, c) into ``hx``, ``hy`` (9, 9)."""
    a, b, c = abc[0], abc[1], abc[2]
    ab = a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    ac = a[0] * c[0] + a[1] * c[1] + a[2] * c[2]
    aa = a[0] * a[0] + a[1] * a[1] + a[2] * a[2]
    bc = b[0] * c[0] + b[1] * c[1] + b[2] * c[2]
    for i in range(3):
        for j in range(3):
            eye = 1.0 if i == j else 0.0
            hx[i, j] = b[i] * c[j] + c[i] * b[j] - 2.0 * bc * eye
            hx[i, 3 + j] = ac * eye + c[i] * a[j] - 2.0 * a[i] * c[j]
            hx[i, 6 + j] = b[i] * a[j] + ab * eye - 2.0 * a[i] * b[j]
            hx[3 + i, 3 + j] = 0.0
            hx[3 + i, 6 + j] = a[i] * a[j] - aa * eye
            hx[6 + i, 6 + j] = 0.0
            ai, aj = a[i] / la, a[j] / la
            hy[i, j] = -((eye - ai * aj) / la * det + ai * cr[0, j] + cr[0, i] * aj)
            hy[i, 3 + j] = -(ai * cr[1, j] - la * _skew(c, i, j))
            hy[i, 6 + j] = -(ai * cr[2, j] + la * _skew(b, i, j))
            hy[3 + i, 3 + j] = 0.0
            hy[3 + i, 6 + j] = la * _skew(a, i, j)
            hy[6 + i, 6 + j] = 0.0
    for i in range(9):
        for j in range(i):
            hx[i, j] = hx[j, i]
            hy[i, j] = hy[j, i]


@kernel
def bending_energy(x, hinge, theta0, weight, kb):
    """Bending energy (J) of all hinges."""
    total = 0.0
    for k in range(hinge.shape[0]):
        i, j, m, n = hinge[k, 0], hinge[k, 1], hinge[k, 2], hinge[k, 3]
        a0, a1, a2 = x[j, 0] - x[i, 0], x[j, 1] - x[i, 1], x[j, 2] - x[i, 2]
        b0, b1, b2 = x[m, 0] - x[i, 0], x[m, 1] - x[i, 1], x[m, 2] - x[i, 2]
        c0, c1, c2 = x[n, 0] - x[i, 0], x[n, 1] - x[i, 1], x[n, 2] - x[i, 2]
        aa = a0 * a0 + a1 * a1 + a2 * a2
        big_x = (a0 * b0 + a1 * b1 + a2 * b2) * (a0 * c0 + a1 * c1 + a2 * c2) - aa * (
            b0 * c0 + b1 * c1 + b2 * c2
        )
        det = a0 * (b1 * c2 - b2 * c1) + a1 * (b2 * c0 - b0 * c2) + a2 * (b0 * c1 - b1 * c0)
        theta = np.arctan2(-np.sqrt(aa) * det, big_x)
        total += kb * weight[k] * (theta - theta0[k]) ** 2
    return total


@kernel
def hinge_angle_derivatives(x, hinge, k, scratch, dtheta, htheta, with_hessian):
    """theta of hinge ``k``; its gradient with respect to (a, b, c) into ``dtheta`` (9,) and, if
    ``with_hessian``, its Hessian into ``htheta`` (9, 9). ``scratch`` is a ``Scratch`` record."""
    abc = scratch.abc
    _edge_vectors(x, hinge, k, abc)
    theta, big_x, big_y, la, det = _angle(abc)
    dx, dy = scratch.dx, scratch.dy
    _first_derivatives(abc, la, det, dx, dy, scratch.cr)
    r2 = big_x * big_x + big_y * big_y
    for i in range(9):
        dtheta[i] = (big_x * dy[i] - big_y * dx[i]) / r2
    if with_hessian:
        hx, hy = scratch.hx, scratch.hy
        _second_derivatives(abc, la, det, scratch.cr, hx, hy)
        for i in range(9):
            for j in range(9):
                v = big_x * hy[i, j] - big_y * hx[i, j] + dx[j] * dy[i] - dy[j] * dx[i]
                htheta[i, j] = (v - dtheta[i] * 2.0 * (big_x * dx[j] + big_y * dy[j])) / r2
    return theta


@kernel
def bending_gradient(x, hinge, theta0, weight, kb, scratch, grad):
    """Adds the bending energy's gradient (N) to ``grad`` (V, 3), from the angle's closed-form
    gradient (module doc): ``dtheta/db = -|a| n1 / |n1|^2``, ``dtheta/dc = -|a| n2 / |n2|^2``,
    ``dtheta/da = -((a.b) dtheta/db + (a.c) dtheta/dc) / (a.a)`` (the angle does not change when
    the hinge turns about its edge), ``dtheta/dx0 = -(dtheta/da + dtheta/db + dtheta/dc)``."""
    abc = scratch.abc
    for k in range(hinge.shape[0]):
        _edge_vectors(x, hinge, k, abc)
        a0, a1, a2 = abc[0, 0], abc[0, 1], abc[0, 2]
        b0, b1, b2 = abc[1, 0], abc[1, 1], abc[1, 2]
        c0, c1, c2 = abc[2, 0], abc[2, 1], abc[2, 2]
        n10, n11, n12 = a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0  # a x b
        n20, n21, n22 = c1 * a2 - c2 * a1, c2 * a0 - c0 * a2, c0 * a1 - c1 * a0  # c x a
        aa = a0 * a0 + a1 * a1 + a2 * a2
        ab = a0 * b0 + a1 * b1 + a2 * b2
        ac = a0 * c0 + a1 * c1 + a2 * c2
        la = np.sqrt(aa)
        big_x = n10 * n20 + n11 * n21 + n12 * n22
        big_y = -la * (n10 * c0 + n11 * c1 + n12 * c2)  # -|a| det(a, b, c)
        theta = np.arctan2(big_y, big_x)
        s = 2.0 * kb * weight[k] * (theta - theta0[k])
        s1 = -s * la / (n10 * n10 + n11 * n11 + n12 * n12)
        s2 = -s * la / (n20 * n20 + n21 * n21 + n22 * n22)
        gb0, gb1, gb2 = s1 * n10, s1 * n11, s1 * n12
        gc0, gc1, gc2 = s2 * n20, s2 * n21, s2 * n22
        wb, wc = -ab / aa, -ac / aa
        ga0, ga1, ga2 = wb * gb0 + wc * gc0, wb * gb1 + wc * gc1, wb * gb2 + wc * gc2
        i, j, m, n = hinge[k, 0], hinge[k, 1], hinge[k, 2], hinge[k, 3]
        grad[i, 0] -= ga0 + gb0 + gc0
        grad[i, 1] -= ga1 + gb1 + gc1
        grad[i, 2] -= ga2 + gb2 + gc2
        grad[j, 0] += ga0
        grad[j, 1] += ga1
        grad[j, 2] += ga2
        grad[m, 0] += gb0
        grad[m, 1] += gb1
        grad[m, 2] += gb2
        grad[n, 0] += gc0
        grad[n, 1] += gc1
        grad[n, 2] += gc2


@kernel
def bending_hessians(x, hinge, theta0, weight, kb, scratch, out):
    """Each hinge's Hessian (N/m) of its bending energy into ``out`` (H, 12, 12) (overwritten),
    degrees of freedom ``3 m + c`` for the hinge's vertex m = 0..3."""
    g, ht, hab = scratch.g, scratch.ht, scratch.hab
    for k in range(hinge.shape[0]):
        theta = hinge_angle_derivatives(x, hinge, k, scratch, g, ht, True)
        s = 2.0 * kb * weight[k]
        dt = theta - theta0[k]
        for i in range(9):
            for j in range(9):
                hab[i, j] = s * (g[i] * g[j] + dt * ht[i, j])
        _to_vertices(hab, out[k])


@kernel(inline="always")
def _to_vertices(hab, out):
    """The 12 x 12 Hessian in (x0..x3) of the 9 x 9 one in (a, b, c), with x0 = -(a + b + c)."""
    for i in range(9):
        for j in range(9):
            out[3 + i, 3 + j] = hab[i, j]
    for c in range(3):
        for j in range(9):
            s = -(hab[c, j] + hab[3 + c, j] + hab[6 + c, j])
            out[c, 3 + j] = s
            out[3 + j, c] = s
    for c in range(3):
        for d in range(3):
            out[c, d] = -(out[c, 3 + d] + out[c, 6 + d] + out[c, 9 + d])
