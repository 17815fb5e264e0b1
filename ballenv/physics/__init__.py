"""The inflated-ring simulator: pure numerics (NumPy + numba), no gymnasium, no torch."""

from .scene import Ground, Ring, Scene
from .simulate import simulate
from .simulation import Simulation, SimulationError, SimulationStats, Trajectory, energy

__all__ = [
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
