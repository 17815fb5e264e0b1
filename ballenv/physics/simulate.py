"""simulate(scene, t_end) -> Trajectory."""

import time
from dataclasses import dataclass, field

import numpy as np

from . import ring as ring_geometry
from .collision import find_contacts
from .energy import ENERGY_PARTS, ring_energy
from .events import EVENT_APEX, event_list
from .model import (
    build_model,
    build_solver,
    build_workspace,
    empty_recording,
    empty_state,
)
from .scene import Scene, check_real
from .stepper import (
    CLOCK_COLLISION_GAIN,
    CLOCK_ENERGY_REMOVED,
    CLOCK_H,
    COUNT_BY_REASON,
    COUNT_ENERGY_PROJECTED,
    COUNT_EVENTS,
    COUNT_IMPULSE_REJECTED,
    COUNT_NEWTON,
    COUNT_RECORDS,
    COUNT_REJECTED,
    COUNT_REJECTION,
    COUNT_STEPS,
    N_CLOCK,
    N_COUNTERS,
    REJECT_ENERGY,
    REJECT_INTRUSION,
    REJECT_NEWTON,
    REJECT_SELF_INTERSECTION,
    REJECTION_REASONS,
    STATUS_BUFFER_FULL,
    STATUS_IMPULSE_AT_DT_MIN,
    STATUS_STEP_TOO_SMALL,
    _record,
    advance,
    initial_state_values,
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
    """Cost of a run: accepted and rejected steps, Newton iterations (linear solves), wall time (s);
    ``rejections`` counts the rejected steps by reason ("newton", "energy", "intrusion",
    "self_intersection", "impulse": the adaptive step's contact impulse above ``impulse_tol``);
    ``energy_projected``: accepted (step, ring) pairs whose energy rose above the ring's budget (its
    start energy plus the work of actuation and collisions) by a small step error, removed from the
    ring's velocities relative to its centre of mass; ``energy_removed`` (J): the sum of those
    excesses (``stepper._within_energy_budget``); ``collision_gain`` (J): the energy ring-ring and
    self-contact impulses created by pushing out nodes that started a step inside the contact
    distance, summed over the steps where their net effect was a gain (the one source of energy
    besides actuation)."""

    steps: int
    rejected_steps: int
    newton_iterations: int
    wall_time: float
    effects: tuple
    integrator: str
    rejections: dict = field(default_factory=dict)  # rejected steps by reason (see REJECTION_REASONS)
    energy_projected: int = 0
    energy_removed: float = 0.0
    collision_gain: float = 0.0


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
    event_table: np.ndarray = field(default=None, repr=False)

    def apexes(self, ring=0):
        """(k, 2) array of (t (s), centre-of-mass height (m)) at the apexes of ``ring``,
        interpolated inside the step (cubic Hermite), not sampled."""
        rows = self.event_table
        if rows is None or len(rows) == 0:
            return np.zeros((0, 2))
        sel = (rows[:, 1] == ring) & (rows[:, 2] == EVENT_APEX)
        return rows[sel][:, [0, 3]]

    def centre_of_mass(self):
        """(T, n_rings, 2) centre of mass (m); nodes of a ring have equal mass."""
        return self.x.mean(axis=2)

    def energy(self):
        """Energy (J) per record and ring: dict of (T, n_rings) arrays.

        Keys: kinetic, stretching, bending, gas (the gas-law potential), gravity, total.
        """
        return energy(self.scene, self.x, self.v)

    def save(self, path):
        """Write this trajectory to ``path`` (a compressed ``.npz``; layout in
        :mod:`ballenv.physics.trajectory_io`); returns the path written."""
        from .trajectory_io import save

        return save(self, path)

    @classmethod
    def load(cls, path):
        """A trajectory saved by :meth:`save`, exactly as it was (ValueError on a foreign file)."""
        from .trajectory_io import load

        return load(path)


def energy(scene, x, v):
    """Mechanical plus gas energy (J) of states ``x, v`` (..., n_rings, n_nodes, 2); see Trajectory."""
    model = build_model(scene)
    x = np.asarray(x, dtype=float)
    v = np.asarray(v, dtype=float)
    lead = x.shape[:-2]
    xs = np.ascontiguousarray(x.reshape(-1, x.shape[-2], 2))
    vs = np.ascontiguousarray(v.reshape(-1, x.shape[-2], 2))
    n_rings = len(scene.rings)
    table = np.zeros((xs.shape[0], len(ENERGY_PARTS)))
    for k in range(xs.shape[0]):
        ring_energy(model, k % n_rings, xs[k], vs[k], table[k])
    out = {name: table[:, j].reshape(lead) for j, name in enumerate(ENERGY_PARTS)}
    out["total"] = table.sum(axis=1).reshape(lead)
    return out


def initial_state(scene):
    """Node positions and velocities (R, N, 2) of the scene's rings at t = 0."""
    pairs = [ring_geometry.initial_nodes(r) for r in scene.rings]
    return np.stack([p[0] for p in pairs]), np.stack([p[1] for p in pairs])


def _check_state(name, value, shape):
    try:
        arr = np.asarray(value)
    except (TypeError, ValueError):  # ragged nesting
        arr = np.asarray(None)
    if arr.dtype.kind not in "iuf":
        raise ValueError(
            f"simulate.{name} = {value!r} is invalid: must be an array of real numbers of shape {shape} "
            "(m or m/s)"
        )
    arr = arr.astype(float)
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
    ws = build_workspace(n_nodes, n_rings)
    shape = (n_rings, n_nodes, 2)
    x_init, v_init = initial_state(scene)
    state = empty_state(n_rings, n_nodes)
    state.x[:] = _check_state("x0", x0, shape) if x0 is not None else x_init
    state.v[:] = _check_state("v0", v0, shape) if v0 is not None else v_init
    _check_above_grounds(model.grounds, state.x)
    if model.collide:
        _check_apart(model, state.x, ws)
    initial_state_values(model, solver, state, ws)
    trial = empty_state(n_rings, n_nodes)
    clock = np.zeros(N_CLOCK)
    clock[CLOCK_H] = solver.dt
    counters = np.zeros(N_COUNTERS, dtype=np.int64)

    capacity = 1 + (int(np.ceil(t_end / output_dt)) + 1 if output_dt else 1024)
    rec = empty_recording(capacity, n_rings, n_nodes, 64 * n_rings)
    _record(model, 0, 0.0, state, rec)
    counters[COUNT_RECORDS] = 1
    bar = _progress_bar(t_end) if progress else None
    chunk = t_end / 100.0 if progress else t_end
    failure = None
    target = 0.0
    while clock[0] < t_end:
        target = min(t_end, max(target, clock[0]) + chunk)
        while True:
            status = advance(
                model, solver, ws, state, trial, clock, counters, target, t_end,
                0.0 if output_dt is None else output_dt, rec,
            )  # fmt: skip
            if status != STATUS_BUFFER_FULL:
                break
            rec = _grown(rec, counters)
        if bar is not None:
            bar.update(clock[0] - bar.n)
        if status == STATUS_IMPULSE_AT_DT_MIN:
            failure = (
                f"the contact impulse per step stayed above Scene.impulse_tol = {scene.impulse_tol:g} N s "
                f"at the smallest step Scene.dt_min = {scene.dt_min:g} s (t = {clock[0]:.6g} s); raise "
                "impulse_tol or lower dt_min."
            )
            break
        if status == STATUS_STEP_TOO_SMALL:
            reason = REJECTION_REASONS.get(int(counters[COUNT_REJECTION]), "the step was rejected")
            failure = (
                f"step size fell below Scene.dt_min = {scene.dt_min:g} s at t = {clock[0]:.6g} s "
                f"(tried {clock[CLOCK_H] * 2:.3g} s): {reason}. The scene may be too stiff or too "
                "violent for its settings; lower Scene.dt or raise Scene.newton_max_iter."
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
        rejections={
            "newton": int(counters[COUNT_BY_REASON + REJECT_NEWTON - 1]),
            "energy": int(counters[COUNT_BY_REASON + REJECT_ENERGY - 1]),
            "intrusion": int(counters[COUNT_BY_REASON + REJECT_INTRUSION - 1]),
            "self_intersection": int(counters[COUNT_BY_REASON + REJECT_SELF_INTERSECTION - 1]),
            "impulse": int(counters[COUNT_IMPULSE_REJECTED]),
        },
        energy_projected=int(counters[COUNT_ENERGY_PROJECTED]),
        energy_removed=float(clock[CLOCK_ENERGY_REMOVED]),
        collision_gain=float(clock[CLOCK_COLLISION_GAIN]),
    )
    n_out = int(counters[COUNT_RECORDS])
    n_ev = int(counters[COUNT_EVENTS])
    traj = Trajectory(
        t=rec.t[:n_out].copy(),
        x=rec.x[:n_out].copy(),
        v=rec.v[:n_out].copy(),
        pressure=rec.pressure[:n_out].copy(),
        contact_force=rec.contact_force[:n_out].copy(),
        events=event_list(rec.events[:n_ev]),
        stats=stats,
        scene=scene,
        event_table=rec.events[:n_ev].copy(),
    )
    if failure is not None:
        raise SimulationError(failure, traj)
    return traj


def _grown(rec, counters):
    """A recording with room for more records and events, holding what ``rec`` has."""
    n_out = int(counters[COUNT_RECORDS])
    n_ev = int(counters[COUNT_EVENTS])
    out_cap = rec.t.shape[0] * (2 if n_out >= rec.t.shape[0] else 1)
    ev_cap = rec.events.shape[0] * 2
    grown = empty_recording(out_cap, rec.x.shape[1], rec.x.shape[2], ev_cap)
    for old, new in zip(rec[:-1], grown[:-1], strict=True):
        new[:n_out] = old[:n_out]
    grown.events[:n_ev] = rec.events[:n_ev]
    return grown


def _check_above_grounds(grounds, x):
    for g, (nx, ny, d, _) in enumerate(grounds):
        phi = x[..., 0] * nx + x[..., 1] * ny - d
        if np.any(phi < 0.0):
            ring, node = np.argwhere(phi < 0.0)[0]
            raise ValueError(
                f"simulate: node {node} of ring {ring} starts {-phi[ring, node]:.3g} m below "
                f"Scene.grounds[{g}]: every node must start on or above every ground"
            )


def _check_apart(model, x, ws):
    count = find_contacts(x, model.thickness, ws.collision)
    inside = ws.collision.contacts[:count]
    inside = inside[inside[:, 5] < 0.0]
    if len(inside):
        a, i, b = (int(v) for v in inside[0, :3])
        raise ValueError(
            f"simulate: node {i} of ring {a} starts inside ring {b}: rings must start apart "
            "(Scene.rings positions and radii, or x0)"
        )


def _progress_bar(t_end):
    from tqdm.auto import tqdm

    return tqdm(
        total=t_end,
        unit="s",
        unit_scale=False,
        desc="simulate",
        bar_format="{l_bar}{bar}| {n:.3g}/{total:.3g} s [{elapsed}<{remaining}]",
    )
