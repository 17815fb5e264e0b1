"""simulate(scene, t_end) -> Trajectory."""

import time
from dataclasses import dataclass, field

import numpy as np

from . import ring as ring_geometry
from .elastic import bend_energy, stretch_energy
from .loads import gas_energy, gravity_energy, polygon_area
from .model import METHOD_GENERALIZED_ALPHA, build_model, build_solver, build_workspace
from .scene import Scene, check_real
from .stepper import (
    CLOCK_H,
    COUNT_NEWTON,
    COUNT_REJECTED,
    COUNT_STEPS,
    N_COUNTERS,
    STATUS_BUFFER_FULL,
    STATUS_STEP_TOO_SMALL,
    advance,
    initial_acceleration,
    ring_pressure,
)


class SimulationError(RuntimeError):
    """The simulation cannot continue (e.g. the step size fell below ``Scene.dt_min``).

    ``trajectory`` holds everything accepted up to the failure.
    """

    def __init__(self, message, trajectory=None):
        super().__init__(message)
        self.trajectory = trajectory


@dataclass(frozen=True)
class SimulationStats:
    """Cost of a run: accepted and rejected steps, Newton iterations (linear solves), wall time (s)."""

    steps: int
    rejected_steps: int
    newton_iterations: int
    wall_time: float
    effects: tuple
    integrator: str


@dataclass
class Trajectory:
    """Recorded states of a simulation (SI units).

    Attributes:
        t: (T,) time (s).
        x: (T, n_rings, n_nodes, 2) node positions (m).
        v: (T, n_rings, n_nodes, 2) node velocities (m/s).
        pressure: (T, n_rings) gauge pressure (Pa); 0 for rings without gas.
        contact_force: (T, n_rings, n_nodes, 2) ground reaction (N); zero without grounds.
        events: list of (t, ring, kind) with kind in {"touchdown", "liftoff", "apex"}.
        stats: :class:`SimulationStats`.
        scene: the simulated :class:`Scene`.
    """

    t: np.ndarray
    x: np.ndarray
    v: np.ndarray
    pressure: np.ndarray
    contact_force: np.ndarray
    events: list
    stats: SimulationStats
    scene: Scene = field(repr=False)

    def centre_of_mass(self):
        """(T, n_rings, 2) centre of mass (m); nodes of a ring have equal mass."""
        return self.x.mean(axis=2)

    def energy(self):
        """Energy (J) per record and ring: dict of (T, n_rings) arrays.

        Keys: kinetic, stretching, bending, gas (the gas-law potential), gravity, total.
        """
        return energy(self.scene, self.x, self.v)


def energy(scene, x, v):
    """Mechanical plus gas energy (J) of states ``x, v`` (..., n_rings, n_nodes, 2); see Trajectory."""
    model = build_model(scene)
    x = np.asarray(x, dtype=float)
    v = np.asarray(v, dtype=float)
    lead = x.shape[:-2]
    xs = x.reshape(-1, x.shape[-2], 2)
    vs = v.reshape(-1, x.shape[-2], 2)
    n_rings = len(scene.rings)
    parts = {k: np.zeros(xs.shape[0]) for k in ("kinetic", "stretching", "bending", "gas", "gravity")}
    for k in range(xs.shape[0]):
        r = k % n_rings
        xk = xs[k]
        m = model.node_mass[r]
        parts["kinetic"][k] = 0.5 * m * float(np.sum(vs[k] ** 2))
        parts["stretching"][k] = stretch_energy(xk, model.rest_len[r], model.ea[r])
        parts["bending"][k] = bend_energy(xk, model.rest_len[r], model.ei[r], model.rest_turn[r])
        if model.pressurised[r]:
            parts["gas"][k] = gas_energy(
                polygon_area(xk),
                model.gas_constant[r],
                model.gas_exponent,
                model.atmospheric_pressure,
                model.width[r],
            )
        if model.use_gravity:
            parts["gravity"][k] = gravity_energy(xk, m, model.gravity)
    out = {k: p.reshape(lead) for k, p in parts.items()}
    out["total"] = sum(out[k] for k in parts)
    return out


def initial_state(scene):
    """Node positions and velocities (R, N, 2) of the scene's rings at t = 0."""
    pairs = [ring_geometry.initial_nodes(r) for r in scene.rings]
    return np.stack([p[0] for p in pairs]), np.stack([p[1] for p in pairs])


def _check_state(name, value, shape):
    arr = np.asarray(value, dtype=float)
    if arr.shape == shape[1:] and shape[0] == 1:
        arr = arr[None]
    if arr.shape != shape:
        raise ValueError(f"simulate.{name} has shape {arr.shape}: must be {shape} (m or m/s)")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"simulate.{name} contains NaN or inf: must be finite")
    return arr.copy()


def simulate(scene, t_end, x0=None, v0=None, output_dt=None, progress=False):
    """Simulate ``scene`` from t = 0 to ``t_end`` (s).

    Args:
        scene: the :class:`Scene`.
        t_end: end time (s), in (0, 1e6].
        x0, v0: optional initial node positions (m) and velocities (m/s), shape (n_rings, n_nodes, 2)
            (or (n_nodes, 2) for one ring); default: the rings' circles and rigid motions.
        output_dt: record interval (s); None records every accepted step.
        progress: show a progress bar (tqdm) over simulated time.

    Returns:
        Trajectory. Raises SimulationError if the step size falls below ``scene.dt_min``.
    """
    if not isinstance(scene, Scene):
        raise ValueError(f"simulate.scene = {scene!r} is invalid: must be a ballenv.physics.Scene")
    t_end = check_real("simulate", "t_end", t_end, 0.0, 1e6, "s", low_open=True)
    if output_dt is not None:
        output_dt = check_real("simulate", "output_dt", output_dt, 0.0, t_end, "s", low_open=True)
    start = time.perf_counter()
    model = build_model(scene)
    solver = build_solver(scene)
    n_rings = len(scene.rings)
    n_nodes = scene.rings[0].n_nodes
    ws = build_workspace(n_nodes)
    shape = (n_rings, n_nodes, 2)
    x_init, v_init = initial_state(scene)
    x = _check_state("x0", x0, shape) if x0 is not None else x_init
    v = _check_state("v0", v0, shape) if v0 is not None else v_init
    a = np.zeros(shape)
    if solver.method == METHOD_GENERALIZED_ALPHA:
        initial_acceleration(model, x, v, a, ws)
    x1, v1, a1 = np.zeros(shape), np.zeros(shape), np.zeros(shape)
    clock = np.array([0.0, solver.dt])
    counters = np.zeros(N_COUNTERS, dtype=np.int64)

    capacity = 1 + (int(np.ceil(t_end / output_dt)) + 1 if output_dt else 1024)
    out_t = np.empty(capacity)
    out_x = np.empty((capacity,) + shape)
    out_v = np.empty((capacity,) + shape)
    out_p = np.empty((capacity, n_rings))
    out_t[0] = 0.0
    out_x[0] = x
    out_v[0] = v
    out_p[0] = [ring_pressure(model, r, x[r]) for r in range(n_rings)]
    n_out = 1
    bar = _progress_bar(t_end) if progress else None
    chunk = t_end / 100.0 if progress else t_end
    failure = None
    target = 0.0
    while clock[0] < t_end:
        target = min(t_end, max(target, clock[0]) + chunk)
        while True:
            status, n_out = advance(
                model, solver, ws, x, v, a, x1, v1, a1, clock, counters, target, t_end,
                0.0 if output_dt is None else output_dt, out_t, out_x, out_v, out_p, n_out,
            )  # fmt: skip
            if status != STATUS_BUFFER_FULL:
                break
            grow = out_t.shape[0]
            out_t = np.concatenate([out_t, np.empty(grow)])
            out_x = np.concatenate([out_x, np.empty((grow,) + shape)])
            out_v = np.concatenate([out_v, np.empty((grow,) + shape)])
            out_p = np.concatenate([out_p, np.empty((grow, n_rings))])
        if bar is not None:
            bar.update(clock[0] - bar.n)
        if status == STATUS_STEP_TOO_SMALL:
            failure = (
                f"step size fell below Scene.dt_min = {scene.dt_min:g} s at t = {clock[0]:.6g} s "
                f"(tried {clock[CLOCK_H] * 2:.3g} s): Newton's iteration did not converge. The scene "
                "may be too stiff or too violent for its settings; lower Scene.dt or raise "
                "Scene.newton_max_iter."
            )
            break
    if bar is not None:
        bar.close()
    stats = SimulationStats(
        steps=int(counters[COUNT_STEPS]),
        rejected_steps=int(counters[COUNT_REJECTED]),
        newton_iterations=int(counters[COUNT_NEWTON]),
        wall_time=time.perf_counter() - start,
        effects=scene.effects,
        integrator=scene.integrator,
    )
    traj = Trajectory(
        t=out_t[:n_out].copy(),
        x=out_x[:n_out].copy(),
        v=out_v[:n_out].copy(),
        pressure=out_p[:n_out].copy(),
        contact_force=np.zeros((n_out,) + shape),
        events=[],
        stats=stats,
        scene=scene,
    )
    if failure is not None:
        raise SimulationError(failure, traj)
    return traj


def _progress_bar(t_end):
    from tqdm.auto import tqdm

    return tqdm(
        total=t_end,
        unit="s",
        unit_scale=False,
        desc="simulate",
        bar_format="{l_bar}{bar}| {n:.3g}/{total:.3g} s [{elapsed}<{remaining}]",
    )
