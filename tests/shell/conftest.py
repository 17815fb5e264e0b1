"""Shared helpers for the shell tests: small models, a step pressed on a ground, dense Hessians and
central differences."""

import numpy as np

from ballenv.shell.rest.modes import element_dofs
from ballenv.shell.scene import Ground, Scene, Shell
from ballenv.shell.simulation import build
from ballenv.shell.skin.model import build_model, build_workspace
from ballenv.shell.step.implicit import start

SLOPE = (-np.sin(0.3), 0.0, np.cos(0.3))  # a ground's normal, tilted 0.3 rad about y


def small_model(subdivisions=1, pressure=1e4, gas_exponent=1.4, **kwargs):
    """A model, its workspace and a randomly deformed configuration (10 % of the radius)."""
    shell = Shell(radius=0.1, subdivisions=subdivisions, pressure=pressure, position=(0, 0, 0), **kwargs)
    model = build_model(shell, gas_exponent=gas_exponent)
    rng = np.random.default_rng(0)
    x = model.rest + 0.01 * rng.standard_normal(model.rest.shape)
    return model, build_workspace(model), x


def pressed_step(integrator="generalized_alpha", seed=3):
    """A small shell pressed on a ground tilted by ``SLOPE``, moving and deforming, with damping and
    friction, in a step of 1 ms: ``(method, step data, its Start, a Newton iterate x, the scene)``."""
    shell = Shell(subdivisions=1, pressure=20e3, position=(0, 0, 0))
    rng = np.random.default_rng(seed)
    x0 = build_model(shell).rest + 2e-4 * rng.standard_normal((42, 3))
    height = float((x0 @ np.array(SLOPE)).min()) - 1e-3
    scene = Scene(
        shells=[shell], grounds=[Ground(normal=SLOPE, height=height, friction=0.4)],
        integrator=integrator, damping=40.0, contact_distance=2e-2, friction_velocity=0.05,
    )  # fmt: skip
    method, (st,) = build(scene)
    v0 = np.array([0.3, 0.1, -0.2]) + 0.05 * rng.standard_normal((42, 3))
    a0 = rng.standard_normal((42, 3))
    sp = start(method, st, x0, v0, a0, 1e-3)
    x = x0 + 1e-3 * v0 + 2e-5 * rng.standard_normal((42, 3))
    return method, st, sp, x, scene


def assemble_dense(elements, mats, n_vertices):
    """The dense (3V, 3V) sum of element matrices."""
    out = np.zeros((3 * n_vertices, 3 * n_vertices))
    d = element_dofs(elements)
    np.add.at(out, (d[:, :, None], d[:, None, :]), mats)
    return out


def central_gradient(f, x, eps=1e-7):
    """Central differences of the scalar ``f`` at ``x`` (any shape)."""
    g = np.zeros(x.size)
    flat = x.reshape(-1)
    for k in range(flat.size):
        xp, xm = flat.copy(), flat.copy()
        xp[k] += eps
        xm[k] -= eps
        g[k] = (f(xp.reshape(x.shape)) - f(xm.reshape(x.shape))) / (2 * eps)
    return g.reshape(x.shape)


def central_jacobian(grad, x, eps=1e-7):
    """Central differences (n, n) of the vector function ``grad`` (returning x's shape) at ``x``."""
    flat = x.reshape(-1)
    out = np.zeros((flat.size, flat.size))
    for k in range(flat.size):
        xp, xm = flat.copy(), flat.copy()
        xp[k] += eps
        xm[k] -= eps
        out[:, k] = (grad(xp.reshape(x.shape)) - grad(xm.reshape(x.shape))).reshape(-1) / (2 * eps)
    return out


def relative_error(a, b):
    """max |a - b| / max |b|."""
    return float(np.abs(a - b).max() / np.abs(b).max())
