"""Linear vibration modes of a shell about its static equilibrium: the generalized eigenproblem

    K v = omega^2 M v

with ``K`` the exact Hessian (N/m) of the total potential at the equilibrium (stretching, bending,
the gas's ``-p d2V`` and rank-one ``dp/dV`` terms) and ``M`` the lumped vertex masses (kg). It is
solved densely (``numpy.linalg.eigh`` on ``M^-1/2 K M^-1/2``, O((3V)^3) time, O((3V)^2) memory), so
for meshes of ``subdivisions <= 3`` (642 vertices) only. A free shell has six rigid-body modes
(``omega ~ 0``).
"""

from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from ..scene import ATMOSPHERIC_PRESSURE, Shell
from ..skin import potential
from ..skin.model import ShellModel, Workspace, build_model, build_workspace
from .equilibrium import equilibrium

MAX_SUBDIVISIONS = 3


class Modes(NamedTuple):
    """Angular frequencies ``omega`` (n,) rad/s, ascending, and mode shapes ``shapes`` (n, V, 3),
    mass-normalised (``sum m_i |v_i|^2 = 1``), about the equilibrium positions ``x`` (V, 3) m."""

    omega: NDArray[np.float64]
    shapes: NDArray[np.float64]
    x: NDArray[np.float64]


def element_dofs(elements: NDArray[np.int64]) -> NDArray[np.int64]:
    """Global degrees of freedom ``3 v + c`` of each element's local ones, (n_elements, 3 n)."""
    return (3 * elements[:, :, None] + np.arange(3)).reshape(len(elements), -1)


def dense_hessian(model: ShellModel, ws: Workspace, x: NDArray[np.float64]) -> NDArray[np.float64]:
    """The exact Hessian (3V, 3V) N/m of the total potential at ``x``, dense."""
    s = potential.hessian(model, ws, x)
    n = x.size
    k = np.zeros((n, n))
    for elements, mats in ((model.triangles, ws.tri_hess), (model.hinges, ws.hinge_hess)):
        d = element_dofs(elements)
        np.add.at(k, (d[:, :, None], d[:, None, :]), mats)
    u = ws.dvol.reshape(-1)
    return k + s * np.outer(u, u)


def modes(
    shell: Shell,
    count: int | None = None,
    gas_exponent: float = 1.0,
    atmospheric_pressure: float = ATMOSPHERIC_PRESSURE,
) -> Modes:
    """The ``count`` lowest (all if None) vibration modes of ``shell`` about its equilibrium under
    its gas alone (gas law of ``gas_exponent``; ``gas_exponent = 0``: a constant pressure, no gas
    stiffness). See the module doc."""
    if shell.subdivisions > MAX_SUBDIVISIONS:
        raise ValueError(
            f"Shell.subdivisions = {shell.subdivisions} is out of range for modes (a dense eigensolver): "
            f"must be an integer in [0, {MAX_SUBDIVISIONS}]"
        )
    model = build_model(shell, gas_exponent, atmospheric_pressure)
    x = equilibrium(shell, gas_exponent=gas_exponent, atmospheric_pressure=atmospheric_pressure).x
    k = dense_hessian(model, build_workspace(model), x)
    w = 1.0 / np.sqrt(np.repeat(model.mass, 3))
    values, vectors = np.linalg.eigh(w[:, None] * k * w[None, :])
    n = len(values) if count is None else int(count)
    shapes = (w[:, None] * vectors[:, :n]).T.reshape(n, -1, 3)
    return Modes(np.sqrt(np.clip(values[:n], 0.0, None)), shapes, x)
