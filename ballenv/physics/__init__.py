"""The inflated-ring simulator: pure numerics (NumPy + numba), no gymnasium, no torch."""

from .scene import Ground, Ring, Scene
from .simulate import SimulationError, SimulationStats, Trajectory, energy, simulate

__all__ = [
    "Ground",
    "Ring",
    "Scene",
    "SimulationError",
    "SimulationStats",
    "Trajectory",
    "energy",
    "simulate",
]
