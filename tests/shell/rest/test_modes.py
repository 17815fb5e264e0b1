"""Vibration modes: the breathing mode of a membrane sphere against omega^2 = 2 E / (rho R^2 (1 - nu)),
the six rigid-body modes, and the dense solver's mesh limit."""

import numpy as np
import pytest

from ballenv.shell import Shell, modes
from ballenv.shell.skin.model import build_model

E, NU, H, R, RHO = 5e6, 0.45, 3e-3, 0.12, 1100.0


def breathing(subdivisions):
    """(omega of the mode most like a uniform radial motion, its overlap with it, all omegas)."""
    shell = Shell(radius=R, subdivisions=subdivisions, youngs_modulus=E, poisson_ratio=NU, thickness=H,
                  density=RHO, pressure=0.0, position=(0, 0, 0))  # fmt: skip
    # gauge pressure 0 and gas_exponent 0: a constant pressure, so the gas adds no stiffness
    result = modes(shell, gas_exponent=0.0)
    mass = build_model(shell).mass
    radial = result.x / np.linalg.norm(result.x, axis=1)[:, None]
    overlap = np.abs(np.einsum("v,nvc,vc->n", mass, result.shapes, radial)) / np.sqrt(mass.sum())
    k = int(np.argmax(overlap))
    return result.omega[k], overlap[k], result.omega


def test_the_breathing_mode_of_a_membrane_sphere():
    omega, overlap, omegas = breathing(3)
    expected = 2 * E / (RHO * R**2 * (1 - NU))
    assert overlap > 0.99
    assert omega**2 / expected == pytest.approx(1.0, abs=0.02)  # measured: +0.014 % (k = 3)
    assert np.all(omegas[:6] < 1e-6 * omega) and omegas[6] > 1e-2 * omega  # six rigid-body modes


def test_modes_refuse_a_mesh_too_large_for_the_dense_solver():
    with pytest.raises(ValueError, match="Shell.subdivisions = 4 is out of range for modes"):
        modes(Shell(subdivisions=4))
