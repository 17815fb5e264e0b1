"""A new force written as an effect module: a constant wind load (the contract's worked example).

Every node of a ring gets the same force ``w`` (N), the ring's own parameters ``(wind_x, wind_y)``
(``parameters``): a potential load, ``E = -sum_i w . x_i`` (J), ``F = -dE/dx = w``, Jacobian 0 in
``x`` and ``v``. On for the rings whose ``w`` is not zero. ``LOAD`` (N per node, per ring index) is
where this example takes its values from; a built-in force would read a Scene or Ring field.
"""

from ballenv.physics.base.jit import kernel

NAME = "wind"
ENERGY_PART = "wind"
LOW_RANK = 0
PARAMETERS = ("wind_x", "wind_y")  # N per node
LOAD = {}  # ring index -> (wind_x, wind_y) N per node; rings not named get no wind


def enabled(scene):
    return any(LOAD.get(r, (0.0, 0.0)) != (0.0, 0.0) for r in range(len(scene.rings)))


def parameters(scene, r):
    return LOAD.get(r, (0.0, 0.0))


@kernel
def on(model, p, r):
    return p[0] != 0.0 or p[1] != 0.0


@kernel
def force(model, p, r, x, v, f):
    for i in range(x.shape[0]):
        f[i, 0] += p[0]
        f[i, 1] += p[1]


@kernel
def jacobian(model, p, r, x, v, coef_x, coef_v, ws, rank):
    return rank


@kernel
def energy(model, p, r, x, v):
    e = 0.0
    for i in range(x.shape[0]):
        e -= p[0] * x[i, 0] + p[1] * x[i, 1]
    return e
