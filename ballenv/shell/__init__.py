"""The 3-D inflated ball: a discrete-shell simulator (pure numerics: NumPy + numba).

The skin (skin/): an icosphere mesh (mesh.py); St. Venant-Kirchhoff membrane triangles
(membrane.py); discrete-shell hinge bending (bending.py); the enclosed gas (gas.py); their total
potential (potential.py); damping of the deformation only (damping.py); the model records (model.py).
The linear algebra (solve/): the envelope Cholesky (envelope.py), the block-sparse assembly
(blocks.py), block-Jacobi-preconditioned CG (cg.py, jointcg.py) and an implicit step's linear solve
(stepsolve.py). At rest (rest/): static equilibrium (equilibrium.py) and linear vibration modes
(modes.py). What the shell touches (touch/): grounds' barriers (ground.py) and motion (motion.py),
lagged Coulomb friction (friction.py), drums' barriers (drum.py), friction (drum_friction.py),
turning (turning.py) and what the step asks of them (drums.py), distances (distance.py), the
barrier between shells and within one with its collision detection (contact.py, projection.py)
and the broad phase (broadphase.py). The time step (step/): the implicit step, backward Euler or
generalized-alpha (implicit.py), its incremental potential (increment.py), its contact vertices'
own descent (relax.py) and records (stepdata.py); the joint step of shells that may touch
(groups.py, joint.py, jointdata.py); the energy budget (budget.py); events (events.py). At the
top: the validated descriptions ``Shell``, ``Ground``, ``Drum``, ``Scene`` (scene.py);
``simulate`` and ``Trajectory`` (simulation.py); fidelity presets (presets.py); regulation balls
and their drop tests (balls.py). SI units.
"""

from ..physics.base.compile_notice import install as _install_compile_notice
from .rest.equilibrium import Equilibrium, EquilibriumError, equilibrium
from .rest.modes import Modes, modes
from .scene import Drum, Ground, Scene, Shell
from .simulation import SimulationError, SimulationStats, Trajectory, simulate
from .skin.mesh import Mesh, icosphere

__all__ = [
    "Drum",
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
