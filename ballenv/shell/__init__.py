"""The 3-D inflated ball: a discrete-shell simulator (pure numerics: NumPy + numba).

An icosphere mesh (mesh.py); St. Venant-Kirchhoff membrane triangles (membrane.py); discrete-shell
hinge bending (bending.py); the enclosed gas (gas.py); their total potential (potential.py); the
envelope Cholesky of its Hessian (envelope.py), its block-sparse assembly (blocks.py) and
block-Jacobi-preconditioned CG (cg.py); static equilibrium (equilibrium.py) and linear vibration
modes (modes.py). The dynamics: the validated descriptions ``Shell``, ``Ground``, ``Scene``
(scene.py); grounds' barriers (ground.py), lagged Coulomb friction (friction.py) and damping of the
deformation only (damping.py); the implicit step, backward Euler or generalized-alpha
(implicit.py), its incremental potential (increment.py), its records (stepdata.py) and its linear
solve (stepsolve.py); contact between shells and within one: distances (distance.py), the barrier
and its collision detection (contact.py, projection.py), the broad phase (broadphase.py) and the
joint step of shells that may touch (groups.py, joint.py, jointdata.py, jointcg.py); the energy
budget (budget.py); events (events.py); ``simulate`` and ``Trajectory`` (simulation.py); fidelity
presets (presets.py); regulation balls and their drop tests (balls.py). SI units.
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
