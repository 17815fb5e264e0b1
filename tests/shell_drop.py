"""A small 3-D ball trajectory made without the simulator (no numba compile): an icosphere moved
along a free-fall parabola, its gauge pressure rising linearly, for the tests of the shell
trajectory files and the 3-D replay page."""

import numpy as np

from ballenv.shell import Ground, Scene, Shell
from ballenv.shell.simulation import SimulationStats, Trajectory
from ballenv.shell.skin.mesh import icosphere

RADIUS = 0.12  # m
HEIGHT = 0.5  # m, the centre's height at t = 0
PRESSURE = (40e3, 60e3)  # Pa, gauge, at the first and the last record


def drop(records=26, t_end=0.25, subdivisions=2, scene=None):
    """The trajectory of one ball falling from rest at ``HEIGHT`` under 9.81 m/s^2 over
    ``[0, t_end]`` s, ``records`` records, above the ground ``z = 0``."""
    scene = scene or Scene(
        shells=[Shell(radius=RADIUS, subdivisions=subdivisions, position=(0.0, 0.0, HEIGHT))],
        grounds=[Ground(friction=0.5)],
    )
    t = np.linspace(0.0, t_end, records)
    centre = np.zeros((records, 3))
    centre[:, 2] = HEIGHT - 0.5 * 9.81 * t**2
    x = icosphere(subdivisions, RADIUS).vertices[None, None] + centre[:, None, None, :]
    v = np.zeros_like(x)
    v[..., 2] = -9.81 * t[:, None, None]
    pressure = np.linspace(*PRESSURE, records)[:, None]
    events = [(0.0, 0, "apex", HEIGHT), (0.2, 0, "touchdown", 0.3)]
    stats = SimulationStats(steps=records - 1, newton_iterations=3 * records, wall_time=0.5)
    return Trajectory(
        t=t, x=x, v=v, contact_force=np.zeros_like(x), pressure=pressure, events=events,
        stats=stats, scene=scene, boundary_work=np.zeros((records, 1)),
    )  # fmt: skip
