"""The records the shell's compiled code reads: ``ShellModel`` (the mesh, its rest geometry, the
material and the gas) and ``Workspace`` (scratch and element matrices), built from a ``Shell``."""

from numbers import Real
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from ..scene import ATMOSPHERIC_PRESSURE, Shell
from . import bending, gas, membrane
from .mesh import icosphere, lumped_masses


class ShellModel(NamedTuple):
    """One shell's arrays and constants (SI units), centred on the origin at rest."""

    rest: NDArray[np.float64]  # (V, 3) m, the stress-free sphere
    triangles: NDArray[np.int64]  # (T, 3), outward
    edges: NDArray[np.int64]  # (E, 2)
    hinges: NDArray[np.int64]  # (E, 4): i, j, k, l (mesh.py)
    beta: NDArray[np.float64]  # (T, 3, 2) 1/m, membrane.py
    area: NDArray[np.float64]  # (T,) m^2, rest areas
    theta0: NDArray[np.float64]  # (E,) rad, rest dihedral angles
    weight: NDArray[np.float64]  # (E,) l^2 / (2 (A1 + A2)) at rest (bending.py)
    mass: NDArray[np.float64]  # (V,) kg, lumped
    lam: float  # Pa, plane-stress Lame constants
    mu: float  # Pa
    thickness: float  # m
    kb: float  # N m, bending stiffness E h^3 / (12 (1 - nu^2))
    gas_exponent: float  # gamma
    atmospheric_pressure: float  # Pa
    absolute_pressure: NDArray[
        np.float64
    ]  # (1,) Pa, p0 + p_atm at the rest volume (the gas amount, set in place)
    rest_volume: float  # m^3, of the rest mesh


class Scratch(NamedTuple):
    """Small scratch arrays of the element kernels."""

    f: NDArray[np.float64]  # (2, 3)
    abc: NDArray[np.float64]  # (3, 3)
    cr: NDArray[np.float64]  # (3, 3)
    dx: NDArray[np.float64]  # (9,)
    dy: NDArray[np.float64]  # (9,)
    g: NDArray[np.float64]  # (9,)
    hx: NDArray[np.float64]  # (9, 9)
    hy: NDArray[np.float64]  # (9, 9)
    ht: NDArray[np.float64]  # (9, 9)
    hab: NDArray[np.float64]  # (9, 9)


class Workspace(NamedTuple):
    """Scratch, element Hessians and the volume gradient of one shell."""

    scratch: Scratch
    tri_hess: NDArray[np.float64]  # (T, 9, 9) N/m: stretching + the gas's -p d2V
    hinge_hess: NDArray[np.float64]  # (E, 12, 12) N/m: bending
    dvol: NDArray[np.float64]  # (V, 3) m^2: dV/dx


def build_model(
    shell: Shell, gas_exponent: float = 1.0, atmospheric_pressure: float = ATMOSPHERIC_PRESSURE
) -> ShellModel:
    """The model of ``shell``: its icosphere, rest geometry, material and gas law (gas.py)."""
    for name, value, high, unit in (
        ("gas_exponent", gas_exponent, 3.0, ""),
        ("atmospheric_pressure", atmospheric_pressure, 1e8, " Pa"),
    ):
        if isinstance(value, bool) or not isinstance(value, Real) or not 0.0 <= float(value) <= high:
            raise ValueError(
                f"{name} = {value!r} is out of range: must be a finite number in [0, {high:g}]{unit}"
            )
    if shell.pressure + atmospheric_pressure <= 0.0:
        raise ValueError(
            f"Shell.pressure = {shell.pressure!r} is out of range: the absolute pressure "
            f"p + atmospheric_pressure ({atmospheric_pressure:g} Pa) must be positive"
        )
    mesh = icosphere(shell.subdivisions, shell.radius)
    beta, area = membrane.rest_frames(mesh.vertices, mesh.triangles)
    theta0, weight = bending.rest_hinges(mesh.vertices, mesh.hinges)
    lam, mu = membrane.lame_plane_stress(shell.youngs_modulus, shell.poisson_ratio)
    return ShellModel(
        rest=mesh.vertices,
        triangles=mesh.triangles,
        edges=mesh.edges,
        hinges=mesh.hinges,
        beta=beta,
        area=area,
        theta0=theta0,
        weight=weight,
        mass=lumped_masses(mesh, shell.density, shell.thickness),
        lam=float(lam),
        mu=float(mu),
        thickness=float(shell.thickness),
        kb=float(shell.bending_stiffness),
        gas_exponent=float(gas_exponent),
        atmospheric_pressure=float(atmospheric_pressure),
        absolute_pressure=np.array([float(shell.pressure + atmospheric_pressure)]),
        rest_volume=float(gas.volume(mesh.vertices, mesh.triangles)),
    )


def build_workspace(model: ShellModel) -> Workspace:
    """A workspace for ``model``."""
    z = np.zeros
    scratch = Scratch(
        z((2, 3)), z((3, 3)), z((3, 3)), z(9), z(9), z(9), z((9, 9)), z((9, 9)), z((9, 9)), z((9, 9))
    )
    n_tri, n_hinge = len(model.triangles), len(model.hinges)
    return Workspace(scratch, z((n_tri, 9, 9)), z((n_hinge, 12, 12)), z((len(model.rest), 3)))


def initial_state(shell: Shell, model: ShellModel) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Positions (V, 3) m and velocities (V, 3) m/s of ``shell`` at rest shape: centred at its
    ``position``, moving with ``velocity`` and spinning with ``angular_velocity`` about its centre."""
    x = model.rest + np.asarray(shell.position)
    v = np.asarray(shell.velocity) + np.cross(np.asarray(shell.angular_velocity), model.rest)
    return x, v
