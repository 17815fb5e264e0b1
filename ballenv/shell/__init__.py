"""The 3-D inflated ball: a discrete-shell simulator (pure numerics: NumPy + numba).

An icosphere mesh (mesh.py); St. Venant-Kirchhoff membrane triangles (membrane.py); discrete-shell
hinge bending (bending.py); the enclosed gas (gas.py); their total potential (potential.py); the
envelope Cholesky of its Hessian (envelope.py) and, for comparison, Jacobi-preconditioned CG
(cg.py); static equilibrium (equilibrium.py) and linear vibration modes (modes.py). SI units.
"""

from ..physics.base.compile_notice import install as _install_compile_notice
from .equilibrium import Equilibrium, EquilibriumError, equilibrium
from .mesh import Mesh, icosphere
from .modes import Modes, modes
from .scene import Shell

__all__ = ["Equilibrium", "EquilibriumError", "Mesh", "Modes", "Shell", "equilibrium", "icosphere", "modes"]

_install_compile_notice()
