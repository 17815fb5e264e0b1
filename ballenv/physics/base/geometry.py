"""Geometry of a ring's polygon: its area, centre of mass and rigid-body motion.

Nodes ``x`` (N, 2) in metres, velocities ``v`` (N, 2) in m/s, equal node masses.
"""

from .cyclic import next_node
from .jit import kernel


@kernel
def polygon_area(x):
    """Shoelace area (m^2) of the ring's polygon; positive for counter-clockwise nodes."""
    n = x.shape[0]
    a = 0.0
    for i in range(n):
        j = next_node(i, n)
        a += x[i, 0] * x[j, 1] - x[j, 0] * x[i, 1]
    return 0.5 * a


@kernel
def centre_of_mass(x, v):
    """Centre of mass (m) and its velocity (m/s) of nodes of equal mass: ``(cx, cy, vx, vy)``."""
    n = x.shape[0]
    cx = cy = vx = vy = 0.0
    for i in range(n):
        cx += x[i, 0]
        cy += x[i, 1]
        vx += v[i, 0]
        vy += v[i, 1]
    return cx / n, cy / n, vx / n, vy / n


@kernel
def rigid_motion(x, v):
    """Centre of mass (m), its velocity (m/s), spin ``omega`` (rad/s) and ``sum |r|^2`` (m^2).

    For equal node masses: ``omega = sum r_i x u_i / sum |r_i|^2`` with ``r_i = x_i - X``.
    """
    n = x.shape[0]
    cx, cy, vx, vy = centre_of_mass(x, v)
    ang = 0.0
    inertia = 0.0
    for i in range(n):
        rx = x[i, 0] - cx
        ry = x[i, 1] - cy
        ang += rx * v[i, 1] - ry * v[i, 0]
        inertia += rx * rx + ry * ry
    return cx, cy, vx, vy, ang / inertia, inertia
