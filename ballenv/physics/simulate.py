"""simulate(scene, t_end) -> Trajectory: a :class:`~.simulation.Simulation` run once to its end."""

from numpy.typing import ArrayLike

from .scene import Scene, check_real
from .simulation import Simulation, SimulationError, Trajectory


def simulate(
    scene: Scene,
    t_end: float,
    x0: ArrayLike | None = None,
    v0: ArrayLike | None = None,
    output_dt: float | None = None,
    progress: bool = False,
) -> Trajectory:
    """Simulate ``scene`` from t = 0 to ``t_end`` (s).

    Args:
        scene: the :class:`Scene`.
        t_end: end time (s), in (0, 1e6].
        x0, v0: optional initial node positions (m) and velocities (m/s), shape (n_rings, n_nodes, 2)
            (or (n_nodes, 2) for one ring); default: the rings' circles and rigid motions. Each ring
            of ``x0`` must be a simple polygon with its nodes counter-clockwise and no two
            neighbours at the same place (ValueError otherwise, before anything is compiled).
        output_dt: record interval (s); None records every accepted step.
        progress: show a progress bar (tqdm) over simulated time.

    Returns:
        Trajectory. Raises SimulationError (with the trajectory up to the failure) if the step size
        falls below ``scene.dt_min``.
    """
    if not isinstance(scene, Scene):
        raise ValueError(f"simulate.scene = {scene!r} is invalid: must be a ballenv.physics.Scene")
    t_end = check_real("simulate", "t_end", t_end, 0.0, 1e6, "s", low_open=True)
    if output_dt is not None:
        output_dt = check_real("simulate", "output_dt", output_dt, 0.0, t_end, "s", low_open=True)
    sim = Simulation(scene, x0, v0, output_dt, expected_end=t_end, caller="simulate")
    if not sim.advance(t_end, progress):
        assert sim.failure is not None  # advance() says why it stopped
        raise SimulationError(sim.failure, sim.trajectory())
    return sim.trajectory()
