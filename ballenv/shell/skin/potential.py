"""The total potential energy of a shell and its derivatives: stretching + bending + gas - the work
of constant point loads ``F`` (N)::

    Pi(x) = W_membrane(x) + W_bending(x) + U(V(x)) - sum_i F_i . x_i     (J)

its gradient (N) and its Hessian (N/m) as element matrices (triangles: stretching and ``-p d2V``;
hinges: bending) plus the rank-one gas term ``s dV dV^T``, ``s = d2U/dV2`` (membrane.py, bending.py,
gas.py).
"""

from ...physics.base.jit import kernel
from .bending import bending_energy, bending_gradient, bending_hessians
from .gas import add_volume_hessians, gas_energy, gas_stiffness, gauge_pressure, volume, volume_gradient
from .membrane import membrane_energy, membrane_gradient, membrane_hessians


@kernel
def energy(model, ws, x, loads):
    """Pi(x) (J)."""
    m = model
    total = membrane_energy(x, m.triangles, m.beta, m.area, m.lam, m.mu, m.thickness, ws.scratch.f)
    total += bending_energy(x, m.hinges, m.theta0, m.weight, m.kb)
    total += gas_energy(m, volume(x, m.triangles))
    for i in range(x.shape[0]):
        for c in range(3):
            total -= loads[i, c] * x[i, c]
    return total


@kernel
def gradient(model, ws, x, loads, grad):
    """dPi/dx (N) into ``grad`` (V, 3); returns the gauge pressure (Pa). Leaves ``ws.dvol`` = dV/dx."""
    m = model
    p = gauge_pressure(m, volume(x, m.triangles))
    volume_gradient(x, m.triangles, ws.dvol)
    for i in range(x.shape[0]):
        for c in range(3):
            grad[i, c] = -p * ws.dvol[i, c] - loads[i, c]
    membrane_gradient(x, m.triangles, m.beta, m.area, m.lam, m.mu, m.thickness, ws.scratch.f, grad)
    bending_gradient(x, m.hinges, m.theta0, m.weight, m.kb, ws.scratch, grad)
    return p


@kernel
def hessian(model, ws, x):
    """The Hessian's element matrices into ``ws.tri_hess``, ``ws.hinge_hess`` and ``dV/dx`` into
    ``ws.dvol``; returns the weight ``s`` (Pa/m^3) of its rank-one part ``s dV dV^T``."""
    m = model
    bending_hessians(x, m.hinges, m.theta0, m.weight, m.kb, ws.scratch, ws.hinge_hess)
    return triangle_hessian(model, ws, x)


@kernel
def triangle_hessian(model, ws, x):
    """The triangles' part of :func:`hessian` (stretching and the gas's ``-p d2V``) into
    ``ws.tri_hess`` and ``dV/dx`` into ``ws.dvol``; returns ``s`` (Pa/m^3). The hinges' matrices
    are left as they are."""
    m = model
    vol = volume(x, m.triangles)
    membrane_hessians(x, m.triangles, m.beta, m.area, m.lam, m.mu, m.thickness, ws.scratch.f, ws.tri_hess)
    add_volume_hessians(x, m.triangles, -gauge_pressure(m, vol), ws.tri_hess)
    volume_gradient(x, m.triangles, ws.dvol)
    return gas_stiffness(m, vol)
