"""Gravity: a uniform field ``g`` (m/s^2), a potential.

``F_i = m g`` (N) on every node; energy ``-sum_i m g . x_i`` (J); no Jacobian. On when
``Scene.gravity`` is not 0.
"""

from typing import TYPE_CHECKING

from ..base.jit import kernel

if TYPE_CHECKING:
    from ..scene import Scene

NAME = "gravity"
ENERGY_PART = "gravity"
LOW_RANK = 0
PARAMETERS = ()


def enabled(scene: "Scene") -> bool:
    """The scene's gravity is not zero."""
    return any(g != 0.0 for g in scene.gravity_vector)


@kernel(inline="always")
def on(model, p, r):
    return model.use_gravity


@kernel(inline="always")
def force(model, p, r, x, v, f):
    """Add ``m g`` (N) to every node of ring ``r``."""
    gravity_force(model.node_mass[r], model.gravity, f)


@kernel(inline="always")
def jacobian(model, p, r, x, v, coef_x, coef_v, ws, rank):
    """A constant force: nothing to add."""
    return rank


@kernel(inline="always")
def energy(model, p, r, x, v):
    """Potential (J) of ring ``r`` in the field."""
    return gravity_energy(x, model.node_mass[r], model.gravity)


@kernel
def gravity_force(node_mass, gravity, f):
    """Add ``F_i = m g`` with ``gravity`` the acceleration vector (m/s^2)."""
    for i in range(f.shape[0]):
        f[i, 0] += node_mass * gravity[0]
        f[i, 1] += node_mass * gravity[1]


@kernel
def gravity_energy(x, node_mass, gravity):
    """Potential (J) ``-sum_i m g . x_i``."""
    e = 0.0
    for i in range(x.shape[0]):
        e -= node_mass * (gravity[0] * x[i, 0] + gravity[1] * x[i, 1])
    return e
