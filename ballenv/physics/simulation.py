"""The one driver of a simulation: build a scene once, advance it, actuate it, read it.

:class:`Simulation` owns a scene's compiled arrays (``Model``, ``Solver``, ``State``, workspace,
clock, counters and the recording) and advances them with :func:`step.stepper.advance`; between
advances the gas amount of a ring can be set and impulses applied (:mod:`ballenv.physics.step.actuation`),
exactly as the env does. :func:`ballenv.physics.simulate` is a Simulation run once to its end; the scenes
that actuate between bounces drive one directly. :class:`SimulationStats` and :class:`Trajectory`
are read off it.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from numbers import Integral
from types import ModuleType
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .base import ring as ring_geometry
from .base.geometry import polygon_area
from .base.layout import (
    CLOCK_BOUNDARY_WORK,
    CLOCK_COLLISION_GAIN,
    CLOCK_ENERGY_REMOVED,
    CLOCK_H,
    CLOCK_T,
    COUNT_BY_REASON,
    COUNT_ENERGY_PROJECTED,
    COUNT_ERROR_REJECTED,
    COUNT_EVENTS,
    COUNT_IMPULSE_REJECTED,
    COUNT_NEWTON,
    COUNT_RECORDS,
    COUNT_REJECTED,
    COUNT_REJECTION,
    COUNT_STEPS,
    GROUND_CENTRE,
    GROUND_DRUM_INSIDE,
    GROUND_KIND,
    GROUND_PLANE,
    GROUND_RADIUS,
    N_CLOCK,
    N_COUNTERS,
    REJECT_NEWTON,
    REJECTION_REASONS,
    REJECTIONS,
    STATUS_BUFFER_FULL,
    STATUS_DONE,
    STATUS_IMPULSE_AT_DT_MIN,
    STATUS_STEP_TOO_SMALL,
)
from .base.record_ref import reference
from .build import (
    build,
    build_drive,
    empty_recording,
    initial_state,
    scene_effects,
    simulation_workspace,
)
from .effects import EFFECTS
from .model import Drive, Model, Recording, Workspace
from .scene import Scene, check_gauge_pressure, check_real, check_vector
from .step.actuation import apply_impulse, hold_gas, ramp_rest_pressure, set_rest_pressure, spread_impulse
from .step.events import event_list
from .step.stepper import advance, initial_state_values, record
from .trajectory import SimulationStats, Trajectory
from .walls.impulses import find_contacts, self_intersects

if TYPE_CHECKING:
    from tqdm.auto import tqdm

EVENT_ROWS_PER_RING = 64  # starting room of the event buffer (it grows)
RECORDS = 1024  # starting room of the recording when every step is recorded (it grows)
# factors on Scene.friction_regularization that Newton's rescue of a step tries in turn (_rescued)
RESCUE_REGULARIZATION = (1.0, 10.0, 100.0)
SHORTEST_EDGE = 1e-6  # shortest edge of a starting ring (fraction of its rest edge length)
# largest |entry| of a starting state: positions as Ring.position's, node speeds 1000 x Ring.velocity's
STATE_BOUNDS = {"x0": (1e6, "m"), "v0": (1e6, "m/s")}


class SimulationError(RuntimeError):
    """The simulation cannot continue (e.g. the step size fell below ``Scene.dt_min``).

    ``trajectory`` holds everything accepted up to the failure.
    """

    def __init__(self, message: str, trajectory: Trajectory | None = None) -> None:
        super().__init__(message)
        self.trajectory = trajectory


class Simulation:
    """A scene's simulation from ``x0, v0`` (default: the rings' circles and rigid motions) at t = 0.

    Args:
        scene: the :class:`Scene`.
        x0, v0: optional initial node positions (m) and velocities (m/s), shape (n_rings, n_nodes, 2)
            (or (n_nodes, 2) for one ring). The contact barriers' stiffness follows the scene's own
            start (``Ring.velocity``, ``angular_velocity``: ``Model.start_energy``), also with these.
        output_dt: record interval (s): records at its multiples (and at the end), interpolated within
            the accepted steps (``step/dense_output.py``: cubic Hermite, exact on a flight
            parabola), so recording neither shortens steps nor changes the run; None records
            every accepted step (the solver's own states).
        expected_end: the time (s) the run is expected to reach, to size the recording (it grows).
        effects: the force effects summed on each ring: the registry ``ballenv.physics.effects.EFFECTS``
            by default, or another list of effect modules (e.g. the registry plus a new force).
        caller: the name error messages give (``simulate`` passes its own).

    ``advance(t)`` steps to time ``t`` (s); ``set_rest_pressure``, ``apply_impulse`` actuate between
    advances; ``trajectory()`` and ``stats()`` read what was recorded. Raises ValueError on invalid
    ``x0``/``v0`` (shape, non-finite, coincident neighbouring nodes, nodes running clockwise, a wall
    crossing itself, below a ground, rings inside each other).
    """

    def __init__(
        self,
        scene: Scene,
        x0: ArrayLike | None = None,
        v0: ArrayLike | None = None,
        output_dt: float | None = None,
        expected_end: float | None = None,
        effects: Sequence[ModuleType] = EFFECTS,
        caller: str = "Simulation",
    ) -> None:
        if not isinstance(scene, Scene):
            raise ValueError(f"{caller}.scene = {scene!r} is invalid: must be a ballenv.physics.Scene")
        if output_dt is not None:
            output_dt = check_real(caller, "output_dt", output_dt, 0.0, 1e6, "s", low_open=True)
        if expected_end is not None:
            expected_end = check_real(caller, "expected_end", expected_end, 0.0, 1e6, "s")
        start = time.perf_counter()
        self.scene = scene
        self.effects = tuple(effects)
        self.output_dt = output_dt
        self.model, self.solver, self.state, self.trial = build(scene, effects)
        self.ws = simulation_workspace(scene, self.model, self.solver, effects)
        n_rings, n_nodes = len(scene.rings), scene.rings[0].n_nodes
        shape = (n_rings, n_nodes, 2)
        x_init, v_init = initial_state(scene)
        self.state.x[:] = _check_state(caller, "x0", x0, shape) if x0 is not None else x_init
        self.state.v[:] = _check_state(caller, "v0", v0, shape) if v0 is not None else v_init
        if x0 is not None:
            _check_ring_shapes(caller, scene, self.state.x)
        _check_above_grounds(caller, self.model.grounds, self.state.x)
        if self.model.collide:
            _check_apart(caller, self.model, self.state.x, self.ws)
        initial_state_values(reference(self.model), self.solver, reference(self.state), reference(self.ws))
        self.clock = np.zeros(N_CLOCK)
        self.clock[CLOCK_H] = self.solver.dt
        self.counters = np.zeros(N_COUNTERS, dtype=np.int64)
        capacity = 1 + (int(np.ceil(expected_end / output_dt)) + 1 if output_dt and expected_end else RECORDS)
        self.rec = empty_recording(capacity, n_rings, n_nodes, EVENT_ROWS_PER_RING * n_rings)
        record(reference(self.model), 0, 0.0, reference(self.state), self.rec)
        self.counters[COUNT_RECORDS] = 1
        self.failure: str | None = None
        self.rescues = 0  # steps Newton's rescue took (_rescued)
        self._rescue_failed = False  # the last stop came after a rescue that failed
        self.drive: Drive | None = None  # actuation spread over time (drive.py), made on first use
        # gauge pressure at rest (Pa) of each ring's gas amount, until a ramp takes it over (Drive.ramp)
        self._rest_pressures = np.array([r.pressure or 0.0 for r in scene.rings])
        self._wall = time.perf_counter() - start  # s: building, then advancing

    @property
    def t(self) -> float:
        """Simulated time (s)."""
        return float(self.clock[CLOCK_T])

    def advance(self, t: float, progress: bool = False) -> bool:
        """Step to time ``t`` (s; steps land on it); with ``progress`` a progress bar over simulated
        time. Returns True, or False when the run cannot go on: ``failure`` then says why (the
        state is the last accepted one). ValueError for a ``t`` before the simulated time."""
        t = check_real("Simulation.advance", "t", t, self.t, 1e6, "s (not before the simulated time)")
        start = time.perf_counter()
        bar = progress_bar(t, self.t) if progress else None
        chunk = t / 100.0 if progress else t
        target = 0.0
        status = STATUS_DONE
        while self.clock[CLOCK_T] < t:
            target = min(t, max(target, self.clock[CLOCK_T]) + chunk)
            status = self._advance_to(target, t)
            if bar is not None:
                bar.update(self.clock[CLOCK_T] - bar.n)
            if status != STATUS_DONE and self._rescued(status, t):
                continue
            if status != STATUS_DONE:
                self.failure = self._failure_message(status)
                break
        if bar is not None:
            bar.close()
        self._wall += time.perf_counter() - start
        return status == STATUS_DONE

    def _advance_to(self, target: float, t_end: float) -> int:
        """Compiled steps until ``target`` (s), landing on ``t_end``; grows the recording when full."""
        while True:
            drive = None if self.drive is None else reference(self.drive)
            status = advance(
                reference(self.model), self.solver, reference(self.ws), reference(self.state),
                reference(self.trial), self.clock, self.counters, target, t_end,
                0.0 if self.output_dt is None else self.output_dt, self.rec, drive,
            )  # fmt: skip
            if status != STATUS_BUFFER_FULL:
                return status
            self.rec = _grown(self.rec, self.counters, self._records_per_step())

    def _records_per_step(self) -> int:
        """The most records one step may write: its end and the output times inside it (a step is
        at most ``Scene.dt`` long; ``step.stepper.records_needed``)."""
        if self.output_dt is None:
            return 1
        return 2 + int(np.ceil(self.scene.dt / self.output_dt))

    def _rescued(self, status: int, t_end: float) -> bool:
        """Newton's rescue of a run that stopped because rejections for Newton failures halved the
        step below ``dt_min`` (``status``): from the last accepted state (the stop left it
        untouched), one step is tried again from ``dt`` with ``Scene.newton_rescue_max_iter``
        iterations allowed, with the scene's friction regularisation ``eps`` and, if that fails
        too, with ``eps`` times each of ``RESCUE_REGULARIZATION[1:]`` in turn (Coulomb friction's
        regularised sign ``v / sqrt(v^2 + eps^2)`` is a near step function of the slip that full
        Newton steps can cycle on at any step size; a larger ``eps`` smooths it). The first that
        converges and passes the acceptance tests is taken; then the run goes on with the scene's
        settings. True if a rescue step was taken (``stopping at t_end`` bounds its step)."""
        cap = self.scene.newton_rescue_max_iter
        if status != STATUS_STEP_TOO_SMALL or self.counters[COUNT_REJECTION] != REJECT_NEWTON:
            return False
        if cap <= self.solver.newton_max_iter:
            return False
        model, solver = self.model, self.solver
        factors = RESCUE_REGULARIZATION if self.model.friction_regularization > 0.0 else (1.0,)
        self._rescue_failed = True
        try:  # (same types in both: the same compiled step)
            self.solver = solver._replace(newton_max_iter=cap)
            for factor in factors:
                self.model = model._replace(friction_regularization=factor * model.friction_regularization)
                self.clock[CLOCK_H] = solver.dt
                if self._advance_to(float(np.nextafter(self.t, np.inf)), t_end) == STATUS_DONE:
                    self.rescues += 1
                    self._rescue_failed = False
                    return True
        finally:
            self.model, self.solver = model, solver
        return False

    def _failure_message(self, status: int) -> str:
        scene, t = self.scene, self.t
        if status == STATUS_IMPULSE_AT_DT_MIN and scene.step_rtol > 0.0:
            rtol = scene.step_rtol
            return (
                f"the contact impulse per step or the local error stayed above Scene.rtol = {rtol:g} "
                f"at the smallest step Scene.dt_min = {scene.dt_min:g} s (t = {t:.6g} s); raise rtol or "
                "atol, or lower dt_min."
            )
        if status == STATUS_IMPULSE_AT_DT_MIN:
            return (
                f"the contact impulse per step stayed above Scene.impulse_tol = {scene.impulse_tol:g} N s "
                f"at the smallest step Scene.dt_min = {scene.dt_min:g} s (t = {t:.6g} s); raise "
                "impulse_tol or lower dt_min."
            )
        assert status == STATUS_STEP_TOO_SMALL, status
        reason = REJECTION_REASONS.get(int(self.counters[COUNT_REJECTION]), "the step was rejected")
        if self._rescue_failed:
            reason += (
                f" (Newton's rescue failed too: {scene.newton_rescue_max_iter} iterations, friction "
                f"regularisation up to {RESCUE_REGULARIZATION[-1]:g} times Scene.friction_regularization)"
            )
        return (
            f"step size fell below Scene.dt_min = {scene.dt_min:g} s at t = {t:.6g} s "
            f"(tried {self.clock[CLOCK_H] * 2:.3g} s): {reason}. The scene may be too stiff or too "
            "violent for its settings; lower Scene.dt or raise Scene.newton_max_iter."
        )

    @property
    def event_count(self) -> int:
        """Event rows recorded so far."""
        return int(self.counters[COUNT_EVENTS])

    def event_rows(self, start: int = 0) -> NDArray[np.float64]:
        """Event rows from ``start`` on: (t (s), ring, kind, centre-of-mass height (m))."""
        return self.rec.events[start : self.event_count].copy()

    def _ring_index(self, owner: str, ring: object) -> int:
        n_rings = len(self.scene.rings)
        if isinstance(ring, bool) or not isinstance(ring, Integral) or not 0 <= int(ring) < n_rings:
            raise ValueError(
                f"{owner}.ring = {ring!r} is out of range: must be an integer in [0, {n_rings - 1}]"
            )
        return int(ring)

    def set_rest_pressure(self, ring: int, pressure: float, duration: float = 0.0) -> None:
        """Set ring ``ring``'s gas to the amount whose gauge pressure at rest is ``pressure`` (Pa)
        (:func:`step.actuation.set_rest_pressure`), in the range ``Ring.pressure`` and the scene's atmosphere
        allow (:func:`scene.check_gauge_pressure`); the ring must hold gas. ``duration`` (s): 0 sets
        it at once; longer moves the amount linearly in time from the present one to it over
        ``[t, t + duration]`` (a gas ramp, :mod:`ballenv.physics.step.actuation`: each step holds the amount
        of its force-evaluation time, steps land on the ramp's end, where the amount is the new one
        exactly), replacing a ramp under way."""
        owner = "Simulation.set_rest_pressure"
        ring = self._ring_index(owner, ring)
        spec = self.scene.rings[ring]
        if spec.pressure is None:
            raise ValueError(f"{owner}: ring {ring} holds no gas (Ring.pressure None)")
        pressure = check_gauge_pressure(owner, "pressure", pressure, spec, self.scene.atmospheric_pressure)
        duration = check_real(owner, "duration", duration, 0.0, 1e6, "s")
        if duration > 0.0:
            model, drive, ws = (reference(r) for r in (self.model, self._driven(), self.ws))
            ramp_rest_pressure(model, drive, ring, pressure, self.t, self.t + duration, ws)
            return
        s = self.state
        model, ws = reference(self.model), reference(self.ws)
        set_rest_pressure(model, ring, pressure, s.x[ring], s.v[ring], s.energy[ring], ws)
        self._rest_pressures[ring] = pressure
        if self.drive is not None:
            hold_gas(model, reference(self.drive), ring, pressure, self.scene.rings[0].n_nodes)

    def apply_impulse(
        self, ring: int, nodes: ArrayLike, impulse: tuple[float, float], duration: float = 0.0
    ) -> None:
        """Add momentum ``impulse`` (N s, a pair, each at most 1e3 N s) to ring ``ring``, shared
        equally by ``nodes`` (distinct node indices of the ring). ``duration`` (s): 0 adds it at
        once; longer delivers it at a constant rate over ``[t, t + duration]`` (a spread impulse,
        :mod:`ballenv.physics.step.actuation`: exactly ``impulse`` whatever the steps, the last one landing on
        the window's end), replacing a spread impulse of the ring under way."""
        owner = "Simulation.apply_impulse"
        ring = self._ring_index(owner, ring)
        n_nodes = self.scene.rings[0].n_nodes
        chosen = np.asarray(nodes)
        if (
            chosen.ndim != 1
            or chosen.dtype.kind not in "iu"
            or len(set(chosen.tolist())) != len(chosen)
            or not np.all((chosen >= 0) & (chosen < n_nodes))
        ):
            raise ValueError(
                f"{owner}.nodes = {nodes!r} is invalid: must be distinct integers in [0, {n_nodes - 1}]"
            )
        jx, jy = check_vector(owner, "impulse", impulse, 1e3, "N s")
        duration = check_real(owner, "duration", duration, 0.0, 1e6, "s")
        nodes = chosen.astype(np.int64)
        if duration > 0.0:
            drive = reference(self._driven())
            spread_impulse(drive, ring, nodes, len(nodes), jx, jy, self.t, self.t + duration)
            return
        s = self.state
        apply_impulse(
            reference(self.model),
            ring,
            s.x[ring],
            s.v[ring],
            s.energy[ring],
            reference(self.ws),
            nodes,
            len(nodes),
            jx,
            jy,
        )

    def _driven(self) -> Drive:
        """The run's :class:`model.Drive`, made on first use (the step then compiles its code; a run
        that never asks for it has ``drive`` None and compiles none)."""
        if self.drive is None:
            n_nodes = self.scene.rings[0].n_nodes
            self.drive = build_drive(len(self.scene.rings), n_nodes)
            for ring, pressure in enumerate(self._rest_pressures):
                hold_gas(reference(self.model), reference(self.drive), ring, float(pressure), n_nodes)
        return self.drive

    def stats(self) -> SimulationStats:
        """:class:`SimulationStats` so far."""
        c, clock = self.counters, self.clock
        return SimulationStats(
            steps=int(c[COUNT_STEPS]),
            rejected_steps=int(c[COUNT_REJECTED]),
            newton_iterations=int(c[COUNT_NEWTON]),
            wall_time=self._wall,
            effects=scene_effects(self.scene, self.effects),
            integrator=self.scene.integrator,
            rejections={
                **{name: int(c[COUNT_BY_REASON + k]) for k, name in enumerate(REJECTIONS)},
                "impulse": int(c[COUNT_IMPULSE_REJECTED]),
                "error": int(c[COUNT_ERROR_REJECTED]),
            },
            energy_projected=int(c[COUNT_ENERGY_PROJECTED]),
            energy_removed=float(clock[CLOCK_ENERGY_REMOVED]),
            collision_gain=float(clock[CLOCK_COLLISION_GAIN]),
            boundary_work=float(clock[CLOCK_BOUNDARY_WORK]),
            newton_rescues=self.rescues,
        )

    def trajectory(self) -> Trajectory:
        """The :class:`Trajectory` recorded so far (copies)."""
        rec = self.rec
        n_out = int(self.counters[COUNT_RECORDS])
        n_ev = int(self.counters[COUNT_EVENTS])
        return Trajectory(
            t=rec.t[:n_out].copy(),
            x=rec.x[:n_out].copy(),
            v=rec.v[:n_out].copy(),
            pressure=rec.pressure[:n_out].copy(),
            contact_force=rec.contact_force[:n_out].copy(),
            events=event_list(rec.events[:n_ev]),
            stats=self.stats(),
            scene=self.scene,
            event_table=rec.events[:n_ev].copy(),
        )


def _check_state(
    caller: str, name: str, value: ArrayLike, shape: tuple[int, int, int]
) -> NDArray[np.float64]:
    try:
        arr = np.asarray(value)
    except (TypeError, ValueError):  # ragged nesting
        arr = np.asarray(None)
    if arr.dtype.kind not in "iuf":
        raise ValueError(
            f"{caller}.{name} = {value!r} is invalid: must be an array of real numbers of shape {shape} "
            "(m or m/s)"
        )
    arr = arr.astype(float)
    if arr.shape == shape[1:] and shape[0] == 1:
        arr = arr[None]
    if arr.shape != shape:
        raise ValueError(f"{caller}.{name} has shape {arr.shape}: must be {shape} (m or m/s)")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{caller}.{name} contains NaN or inf: must be finite")
    bound, unit = STATE_BOUNDS[name]
    if np.any(np.abs(arr) > bound):
        raise ValueError(
            f"{caller}.{name} has an entry of {np.abs(arr).max():.3g} {unit}: "
            f"each must be in [-{bound:g}, {bound:g}]"
        )
    return arr.copy()


def _check_ring_shapes(caller: str, scene: Scene, x: NDArray[np.float64]) -> None:
    """Refuse starting node positions ``x`` (R, N, 2) m on which the wall's forces are undefined or
    the step cannot start: neighbouring nodes (almost) at the same place, nodes running clockwise
    (the gas would pull the wall inward), or, when the scene rejects such states, a self-crossing
    wall."""
    for r, (ring, nodes) in enumerate(zip(scene.rings, x, strict=True)):
        edges = np.linalg.norm(np.roll(nodes, -1, axis=0) - nodes, axis=1)
        shortest = SHORTEST_EDGE * ring_geometry.rest_edge_length(ring.radius, ring.n_nodes)
        i = int(np.argmin(edges))
        if edges[i] <= shortest:
            raise ValueError(
                f"{caller}.x0: nodes {i} and {(i + 1) % len(nodes)} of ring {r} are {edges[i]:.3g} m apart: "
                f"neighbouring nodes must be more than {shortest:.3g} m apart ({SHORTEST_EDGE:g} of the "
                "rest edge length)"
            )
        area = polygon_area(nodes)
        if area <= 0.0:
            raise ValueError(
                f"{caller}.x0: the nodes of ring {r} run clockwise (signed area {area:.3g} m^2): they must "
                "be in counter-clockwise order, as on the ring's circle (reverse their order)"
            )
        if scene.self_intersection != "ignore" and self_intersects(nodes):
            raise ValueError(
                f"{caller}.x0: the wall of ring {r} crosses itself: it must be a simple "
                "polygon (Scene.self_intersection = 'barrier' or 'reject' refuses every self-crossing state)"
            )


def _grown(rec: Recording, counters: NDArray[np.int64], per_step: int) -> Recording:
    """A recording holding what ``rec`` has, with twice the room for records if fewer than
    ``per_step`` (the most one step may write) are left, and for events if fewer than a step's
    (three per ring) are left."""
    n_out = int(counters[COUNT_RECORDS])
    n_ev = int(counters[COUNT_EVENTS])
    out_cap = rec.t.shape[0]
    while n_out + per_step > out_cap:
        out_cap *= 2
    ev_cap = rec.events.shape[0]
    if n_ev + 3 * rec.x.shape[1] > ev_cap:
        ev_cap *= 2
    grown = empty_recording(out_cap, rec.x.shape[1], rec.x.shape[2], ev_cap)
    for old, new in zip(rec[:-1], grown[:-1], strict=True):
        new[:n_out] = old[:n_out]
    grown.events[:n_ev] = rec.events[:n_ev]
    return grown


def _check_above_grounds(caller: str, grounds: NDArray[np.float64], x: NDArray[np.float64]) -> None:
    n_planes = int(np.sum(grounds[:, GROUND_KIND] == GROUND_PLANE))
    for g, row in enumerate(grounds):
        side = row[GROUND_KIND]
        if side == GROUND_PLANE:
            nx, ny, d = row[:3]  # d = d(0)
            phi = x[..., 0] * nx + x[..., 1] * ny - d
            where = f"below Scene.grounds[{g}]: every node must start on or above every ground"
        else:
            cx, cy = row[GROUND_CENTRE : GROUND_CENTRE + 2]
            phi = side * (np.hypot(x[..., 0] - cx, x[..., 1] - cy) - row[GROUND_RADIUS])
            inside = "inside" if side == GROUND_DRUM_INSIDE else "outside"
            where = f"outside Scene.drums[{g - n_planes}]: every node must start {inside} the drum"
        if np.any(phi < 0.0):
            ring, node = np.argwhere(phi < 0.0)[0]
            raise ValueError(f"{caller}: node {node} of ring {ring} starts {-phi[ring, node]:.3g} m {where}")


def _check_apart(caller: str, model: Model, x: NDArray[np.float64], ws: Workspace) -> None:
    count = find_contacts(x, model.thickness, ws.collision)
    inside = ws.collision.contacts[:count]
    inside = inside[inside[:, 5] < 0.0]
    if len(inside):
        a, i, b = (int(v) for v in inside[0, :3])
        raise ValueError(
            f"{caller}: node {i} of ring {a} starts inside ring {b}: rings must start apart "
            "(Scene.rings positions and radii, or x0)"
        )


def progress_bar(t_end: float, start: float = 0.0) -> tqdm[Any]:
    """A tqdm bar over simulated time (s) from ``start`` to ``t_end``; ``update`` it by the time
    advanced and ``close`` it."""
    from tqdm.auto import tqdm

    return tqdm(
        total=t_end,
        initial=start,
        unit="s",
        unit_scale=False,
        desc="simulate",
        bar_format="{l_bar}{bar}| {n:.3g}/{total:.3g} s [{elapsed}<{remaining}]",
    )


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
        output_dt: record interval (s): records at its multiples (and at the end), interpolated within
            the accepted steps (``step/dense_output.py``: cubic Hermite, exact on a flight
            parabola), so recording neither shortens steps nor changes the run; None records
            every accepted step (the solver's own states).
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
