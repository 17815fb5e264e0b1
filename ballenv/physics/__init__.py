"""The inflated-ring simulator: pure numerics (NumPy + numba), no gymnasium, no torch."""

from .base.compile_notice import install as _install_compile_notice
from .scene import Drum, Ground, Ring, Scene
from .simulation import Simulation, SimulationError, simulate
from .trajectory import SimulationStats, Trajectory, energy

__all__ = [
    "Drum",
    "Ground",
    "Ring",
    "Scene",
    "Simulation",
    "SimulationError",
    "SimulationStats",
    "Trajectory",
    "energy",
    "simulate",
]

_install_compile_notice()
