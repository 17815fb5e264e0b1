"""The 3-D inflated ball: a discrete-shell simulator (pure numerics: NumPy + numba).

An icosphere mesh (mesh.py); St. Venant-Kirchhoff membrane triangles (membrane.py); discrete-shell
hinge bending (bending.py); the enclosed gas (gas.py); their total potential (potential.py); the
envelope Cholesky of its Hessian (envelope.py) and, for comparison, Jacobi-preconditioned CG
(cg.py); static equilibrium (equilibrium.py), linear vibration modes (modes.py), and one implicit
backward-Euler step (implicit.py) with gravity and a flat ground's contact barrier (ground.py).
SI units.
"""

from ..physics.base.compile_notice import install as _install_compile_notice
from .equilibrium import Equilibrium, EquilibriumError, equilibrium
from .mesh import Mesh, icosphere
from .modes import Modes, modes
from .scene import Ground, Scene, Shell
from .simulation import SimulationError, SimulationStats, Trajectory, simulate

__all__ = [
    "Equilibrium",
    "EquilibriumError",
    "Ground",
    "Mesh",
    "Modes",
    "Scene",
    "Shell",
    "SimulationError",
    "SimulationStats",
    "Trajectory",
    "equilibrium",
    "icosphere",
    "modes",
    "simulate",
]

_install_compile_notice()
