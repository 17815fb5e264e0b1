"""Many bouncing balls advanced in one compiled call: the physics behind InflatedBall-v3.

Every env holds one ring above one flat ground; the rings share material and numerical settings
and differ in state, gas and target. One :class:`Model` with per-ring arrays of length E holds all
envs; env ``e`` is advanced by the same ``step.stepper.advance`` as ``simulate()``, on views of its
slices, with its own clock and step size. A batch of E envs therefore gives the same numbers as E
batches of one (the single env is a batch of one).

A control step of env ``e``: start the action (a gas ramp to the new setpoint, or a paddle strike
spread over its duration: ``physics/step/actuation.py``), advance to ``(k + 1) * control_dt`` (the steps
deliver it), and tally the apex events of the interval. Only an apex in flight counts
(after a lift-off, before the next touchdown): the centre of mass also turns round inside a squash.
"""

import math
from collections.abc import Callable, Mapping
from concurrent.futures import ThreadPoolExecutor
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ballenv.physics.base.geometry import centre_of_mass
from ballenv.physics.base.jit import kernel, python_entry
from ballenv.physics.base.layout import (
    CLOCK_H,
    CLOCK_T,
    COUNT_EVENTS,
    COUNT_RECORDS,
    ENERGY_BUDGET,
    ENERGY_TOTAL,
    EVENT,
    GROUND_NORMAL,
    N_CLOCK,
    N_COUNTERS,
    STATUS_BUFFER_FULL,
    STATUS_DONE,
)
from ballenv.physics.base.record_ref import RecordRef
from ballenv.physics.build import build, build_drive, build_workspace
from ballenv.physics.effects.gas import ring_pressure
from ballenv.physics.ground.contact import FREE
from ballenv.physics.model import PER_RING_FIELDS, Recording, Workspace, rings_view
from ballenv.physics.step.actuation import (
    hold_gas,
    rest_circle_radius,
    restart,
    set_gas,
    stop_push,
)
from ballenv.physics.step.stepper import advance

from .observation import (
    OBS_CENTRE_OF_MASS_POSITION,
    OBS_CENTRE_OF_MASS_VELOCITY,
    OBS_GROUND_NORMAL_FORCE,
    OBS_LAST_APEX,
    OBS_NODE_POSITION,
    OBS_NODE_VELOCITY,
    OBS_PADDLE_HEIGHT,
    OBS_PADDLE_IMPULSE,
    OBS_PADDLE_IN_REACH,
    OBS_PRESSURE,
    OBS_PRESSURE_SETPOINT,
    OBS_TARGET_HEIGHT,
    field_start,
)
from .observation import size as layout_size
from .observation import structure as layout_structure
from .task import (
    END_NONE,
    MODE_PADDLE,
    REWARD,
    Task,
    actuate,
    env_ring,
    outcome,
    paddle_ready,
    rise,
    tally,
)
from .tickets import draw_ticket

if TYPE_CHECKING:
    from ..physics.scene import Scene

NO_OUTPUT = 1e300  # output interval of advance(): record only at the end of the control step
EVENT_ROWS = 32
ENVS_PER_LINE = 8  # envs of a float64 or int64 per-env array in one 64-byte cache line


@kernel
def env_model(model, e):
    """The one-ring Model of env ``e`` (views of its per-ring fields, ``model.PER_RING_FIELDS``)."""
    return rings_view(model, e, e + 1)


@kernel
def env_state(state, e):
    """The one-ring State (or Drive) of env ``e`` (views of its slices)."""
    return rings_view(state, e, e + 1)


@kernel
def reset_env(
    model,
    solver,
    ws,
    state,
    drive,
    clocks,
    counters,
    task,
    e,
    centre,
    velocity,
    phase,
    target,
    pressure,
    obs,
    low,
    high,
    out,
):
    """Put env ``e``'s ring on its inflated circle for gas ``pressure`` (Pa) at ``centre`` (m), turned
    by ``phase`` (rad), moving rigidly with ``velocity`` (m/s); target apex ``target`` (m). Writes its
    observation as :func:`step_batch` does. No gas ramp or strike is under way (``drive``)."""
    me = env_model(model, e)
    se = env_state(state, e)
    de = env_state(drive, e)
    ring = env_ring()
    x = se.x[0]
    v = se.v[0]
    n = x.shape[0]
    radius = model.radius[e]
    if model.pressurised[e]:
        radius = rest_circle_radius(me, ring, pressure, n)
    for i in range(n):
        theta = phase + 2.0 * math.pi * i / n
        x[i, 0] = centre[0] + radius * math.cos(theta)
        x[i, 1] = centre[1] + radius * math.sin(theta)
        v[i, 0] = velocity[0]
        v[i, 1] = velocity[1]
        se.active[0, i] = FREE
        se.contact_force[0, i, 0] = 0.0
        se.contact_force[0, i, 1] = 0.0
    if model.pressurised[e]:
        set_gas(me, ring, pressure, n, ws)  # restart() counts the energy
    hold_gas(me, de, ring, pressure, n)
    stop_push(de, ring)
    restart(me, ring, x, v, se.a[0], se.active[0], se.energy[0], ws)
    se.energy[0, ENERGY_BUDGET] = se.energy[0, ENERGY_TOTAL]  # a new episode starts a new budget
    clocks[e, :] = 0.0
    clocks[e, CLOCK_H] = solver.dt
    counters[e, :] = 0
    task.target[e] = target
    task.setpoint[e] = pressure
    task.rest_radius[e] = radius
    task.paddle_height[e] = target + radius
    task.airborne[e] = True
    task.last_apex[e] = centre[1] - task.ground_height  # released at rest: the start is an apex
    task.steps[e] = 0
    task.apex_count[e] = 0
    task.apex_error[e] = 0.0
    task.apex_height[e] = 0.0
    task.impulse[e] = 0.0
    task.struck[e] = False
    task.in_reach[e] = paddle_ready(task, e, x, v)
    task.status[e] = STATUS_DONE
    task.rise[e] = rise(me, se, task, e)
    task.reward[e, :] = 0.0
    task.end[e] = END_NONE
    observe_env(model, state, task, e, obs[e])
    _clip(obs[e], low, high, out[e])


@kernel(inline="always")
def step_env(
    model, solver, ws, state, trial, drive, clocks, counters, records, events, task, e, action, nodes, obs,
    low, high, out,
):  # fmt: skip
    """One control step of env ``e``: actuate with ``action`` in [-1, 1] (its gas ramp or strike in
    ``drive``), advance to its next control time, tally its flight apexes, then write its
    observation (``obs[e]``, unclipped; ``out[e]``, clipped to ``[low, high]`` as float32) and reward
    and end (``task.reward``, ``task.end``, see :func:`outcome`). ``ws`` and ``nodes`` are scratch,
    carried over nothing."""
    me = env_model(model, e)
    se = env_state(state, e)
    te = env_state(trial, e)
    de = env_state(drive, e)
    task.apex_count[e] = 0
    task.apex_error[e] = 0.0
    task.apex_height[e] = 0.0
    actuate(me, se, de, task, e, action, clocks[e, CLOCK_T], ws, nodes)
    t_next = (task.steps[e] + 1) * task.control_dt
    rec = Recording(
        records.t[e], records.x[e], records.v[e], records.pressure[e], records.contact_force[e], events[e]
    )
    counters[e, COUNT_RECORDS] = 0
    while True:
        counters[e, COUNT_EVENTS] = 0
        status = advance(me, solver, ws, se, te, clocks[e], counters[e], t_next, t_next, NO_OUTPUT, rec, de)
        tally(task, e, events[e], counters[e, COUNT_EVENTS])
        if status != STATUS_BUFFER_FULL:
            break
    task.status[e] = status
    task.steps[e] += 1
    task.rise[e] = rise(me, se, task, e)
    task.in_reach[e] = paddle_ready(task, e, se.x[0], se.v[0])
    observe_env(model, state, task, e, obs[e])
    _clip(obs[e], low, high, out[e])
    outcome(task, e, obs[e], state.x.shape[1])


@kernel(nogil=True)
def step_batch(
    model, solver, ws, state, trial, drive, clocks, counters, records, events, task, actions, active,
    chunks, tickets, nodes, obs, low, high, out,
):  # fmt: skip
    """One control step (:func:`step_env`) of every env ``e`` with ``active[e]``, with action
    ``actions[e]``, chunk by chunk: chunk ``k`` is envs ``chunks[k]`` to ``chunks[k + 1] - 1``, and
    the call steps the chunks whose numbers it draws from ``tickets`` (:func:`.tickets.draw_ticket`)
    until none are left. Runs without the GIL: threads calling it at once, each with its own
    scratch ``ws``, ``nodes``, share the chunks out between them, each chunk to the first thread free
    to draw it."""
    while True:
        k = draw_ticket(tickets)
        if k >= chunks.shape[0] - 1:
            return
        for e in range(chunks[k], chunks[k + 1]):
            if active[e]:
                step_env(
                    model, solver, ws, state, trial, drive, clocks, counters, records, events, task, e,
                    actions[e], nodes, obs, low, high, out,
                )  # fmt: skip


@kernel
def _clip(row, low, high, out):
    for k in range(row.shape[0]):
        out[k] = min(high[k], max(low[k], row[k]))


@kernel
def observe_env(model, state, task, e, row):
    """Write env ``e``'s observation (the fields of ``observation.FIELDS``, unclipped) into ``row``."""
    n = state.x.shape[1]
    nx, ny = model.grounds[0, GROUND_NORMAL], model.grounds[0, GROUND_NORMAL + 1]
    x = state.x[e]
    v = state.v[e]
    cx, cy, ux, uy = centre_of_mass(x, v)
    position = field_start(OBS_NODE_POSITION, n)
    velocity = field_start(OBS_NODE_VELOCITY, n)
    force = field_start(OBS_GROUND_NORMAL_FORCE, n)
    for i in range(n):
        row[position + 2 * i] = x[i, 0] - cx
        row[position + 2 * i + 1] = x[i, 1] - cy
        row[velocity + 2 * i] = v[i, 0] - ux
        row[velocity + 2 * i + 1] = v[i, 1] - uy
        f = state.contact_force[e, i]
        row[force + i] = f[0] * nx + f[1] * ny
    centre = field_start(OBS_CENTRE_OF_MASS_POSITION, n)
    row[centre] = cx
    row[centre + 1] = cy - task.ground_height
    centre_velocity = field_start(OBS_CENTRE_OF_MASS_VELOCITY, n)
    row[centre_velocity] = ux
    row[centre_velocity + 1] = uy
    row[field_start(OBS_PRESSURE, n)] = ring_pressure(env_model(model, e), env_ring(), x)
    row[field_start(OBS_PRESSURE_SETPOINT, n)] = task.setpoint[e]
    row[field_start(OBS_TARGET_HEIGHT, n)] = task.target[e]
    row[field_start(OBS_LAST_APEX, n)] = task.last_apex[e]
    if task.mode == MODE_PADDLE:
        row[field_start(OBS_PADDLE_HEIGHT, n)] = task.paddle_height[e]
        row[field_start(OBS_PADDLE_IN_REACH, n)] = 1.0 if task.in_reach[e] else 0.0
        row[field_start(OBS_PADDLE_IMPULSE, n)] = task.impulse[e]


def observation_size(n_nodes: int, mode: int) -> int:
    """Length of the observation vector in action mode ``mode`` (see ``observation.FIELDS``)."""
    return layout_size(n_nodes, mode == MODE_PADDLE)


def observation_structure(n_nodes: int, mode: int) -> dict[str, slice]:
    """Name -> slice of the observation vector in action mode ``mode`` (see ``observation.FIELDS``)."""
    return layout_structure(n_nodes, mode == MODE_PADDLE)


class BallBatch:
    """E envs' arrays and the compiled calls that reset and step them.

    ``obs`` (E, D) float32 holds the observations clipped to ``[low, high]``; ``task.reward`` the
    reward and its terms, ``task.end`` how each episode ended (``END_*``).

    With ``threads`` > 1 a step is cut into contiguous chunks of envs (:func:`guided_chunks`); each
    thread (the caller's and ``threads - 1`` others) makes one :func:`step_batch` call (without the
    GIL) with its own scratch, and inside it draws the chunks one after the other, each going to the
    first thread free: envs cost unequal and changing amounts (a bounce, a strike), so fixed shares
    would leave one thread waiting. Chunks write disjoint, contiguous rows and scratch carries
    nothing from one env to the next: every env's numbers are those of one thread, to the bit."""

    def __init__(
        self,
        scene: "Scene",
        n_envs: int,
        task_settings: Mapping[str, Any],
        low: ArrayLike,
        high: ArrayLike,
        threads: int = 1,
    ) -> None:
        self.scene = scene
        self.n_envs = n_envs
        self.n_nodes = scene.rings[0].n_nodes
        self.model, self.solver, self.state, self.trial = build(scene, copies=n_envs)
        self.drive = build_drive(n_envs, self.n_nodes)  # each env's gas ramp and paddle strike
        barrier = bool(self.model.self_barrier)
        self.ws = self._scratch_workspace(barrier)
        self.clocks = np.zeros((n_envs, N_CLOCK))
        self.counters = np.zeros((n_envs, N_COUNTERS), dtype=np.int64)
        shape = (n_envs, 1, 1, self.n_nodes, 2)
        self.records = Recording(
            t=np.zeros((n_envs, 1)),
            x=np.zeros(shape),
            v=np.zeros(shape),
            pressure=np.zeros((n_envs, 1, 1)),
            contact_force=np.zeros(shape),
            events=np.zeros((n_envs, EVENT_ROWS, EVENT.size)),
        )
        zeros = np.zeros(n_envs)
        self.task = Task(
            **task_settings,
            target=zeros.copy(),
            setpoint=zeros.copy(),
            rest_radius=zeros.copy(),
            paddle_height=zeros.copy(),
            airborne=np.ones(n_envs, dtype=np.bool_),
            last_apex=zeros.copy(),
            steps=np.zeros(n_envs, dtype=np.int64),
            apex_count=np.zeros(n_envs, dtype=np.int64),
            apex_error=zeros.copy(),
            apex_height=zeros.copy(),
            impulse=zeros.copy(),
            in_reach=np.zeros(n_envs, dtype=np.bool_),
            struck=np.zeros(n_envs, dtype=np.bool_),
            status=np.zeros(n_envs, dtype=np.int64),
            rise=zeros.copy(),
            reward=np.zeros((n_envs, REWARD.size)),
            end=np.zeros(n_envs, dtype=np.int64),
        )
        self.nodes = np.zeros(self.n_nodes, dtype=np.int64)
        # the records the compiled calls take by reference (one pointer each; record_ref.py)
        self._refs = tuple(RecordRef(r) for r in (self.model, self.state, self.trial, self.drive))
        self.threads = max(1, min(int(threads), n_envs))
        self._pool: ThreadPoolExecutor | None = None
        # chunk boundaries (one chunk of all envs on one thread) and the counter their numbers are drawn from
        self._chunks = np.array(guided_chunks(n_envs, self.threads) if self.threads > 1 else [0, n_envs])
        self._tickets = np.zeros(1, dtype=np.int64)
        self._ws_ref = RecordRef(self.ws)
        if self.threads > 1:
            self._pool = ThreadPoolExecutor(self.threads - 1, thread_name_prefix="ballenv")
            self._scratch = [(self._ws_ref, self.nodes)] + [
                (RecordRef(self._scratch_workspace(barrier)), np.zeros(self.n_nodes, dtype=np.int64))
                for _ in range(self.threads - 1)
            ]
        self.low = np.asarray(low, dtype=np.float64)
        self.high = np.asarray(high, dtype=np.float64)
        self.raw = np.zeros((n_envs, observation_size(self.n_nodes, self.task.mode)))
        self.obs = np.zeros(self.raw.shape, dtype=np.float32)
        self.all = np.ones(n_envs, dtype=np.bool_)
        self._step_batch: Callable[..., None] | None = (
            None  # the compiled entry point of the step call, once known
        )

    def _scratch_workspace(self, barrier: bool) -> Workspace:
        """A thread's scratch: one ring, with the barrier's if the scene has it, never ring pairs
        (the envs' rings never meet). None in their places: the step compiles none of their code."""
        return build_workspace(self.n_nodes, barrier=barrier, ring_pairs=False)

    def reset(
        self, e: int, centre: ArrayLike, velocity: ArrayLike, phase: float, target: float, pressure: float
    ) -> None:
        """Start env ``e`` afresh (see :func:`reset_env`)."""
        model, state, _, drive = self._refs
        reset_env(
            model, self.solver, self._ws_ref, state, drive, self.clocks, self.counters, self.task,
            e, np.asarray(centre, dtype=float), np.asarray(velocity, dtype=float), float(phase),
            float(target), float(pressure), self.raw, self.low, self.high, self.obs,
        )  # fmt: skip

    def step(self, actions: ArrayLike, active: ArrayLike | None = None) -> None:
        """One control step of the envs marked in ``active`` (all by default); ``actions`` (E,)
        float64 in [-1, 1]."""
        active = self.all if active is None else np.ascontiguousarray(active, dtype=np.bool_)
        actions = np.ascontiguousarray(actions, dtype=np.float64)
        self._tickets[0] = 0
        if self._pool is None:
            self._step(self._ws_ref, self.nodes, actions, active)
            return
        if self._step_batch is None:  # compile or load, once, before the threads call it
            self._step(self._ws_ref, self.nodes, actions, np.zeros_like(active))
            self._tickets[0] = 0
        calls = [self._pool.submit(self._step, ws, nodes, actions, active) for ws, nodes in self._scratch[1:]]
        try:
            self._step(*self._scratch[0], actions, active)
        finally:  # every thread done before this returns or raises
            for call in calls:
                call.result()

    def _step(
        self, ws: RecordRef, nodes: NDArray[np.int64], actions: NDArray[np.float64], active: NDArray[np.bool_]
    ) -> None:
        """One :func:`step_batch` call with scratch ``ws`` (a Workspace's RecordRef), ``nodes``: the
        chunks it draws."""
        model, state, trial, drive = self._refs
        args = (
            model, self.solver, ws, state, trial, drive, self.clocks, self.counters,
            self.records, self.records.events, self.task, actions, active, self._chunks, self._tickets,
            nodes, self.raw, self.low, self.high, self.obs,
        )  # fmt: skip
        if self._step_batch is None:
            self._step_batch = compiled_entry(step_batch, args)
        self._step_batch(*args)

    def env_arrays(self) -> dict[str, NDArray[Any]]:
        """Every array with one row per env (leading axis E), by name: an env's whole state (its
        model rows, where a reset sets the gas, included). The workspace is scratch, not state."""
        arrays = {f"model.{name}": getattr(self.model, name) for name in PER_RING_FIELDS}
        for group in ("drive", "state", "trial", "records", "task"):
            record = getattr(self, group)
            arrays.update(
                (f"{group}.{name}", value)
                for name, value in zip(record._fields, record, strict=True)
                if isinstance(value, np.ndarray)
            )
        arrays.update(clocks=self.clocks, counters=self.counters, raw=self.raw, obs=self.obs)
        return arrays

    def copy_env(self, source: "BallBatch", e: int, rows: ArrayLike) -> None:
        """Set envs ``rows`` of this batch to env ``e`` of ``source`` (a batch of the same scene and
        task settings; it may be this one): from here they step exactly as env ``e`` would, to the
        bit. What lookahead planning needs: try actions on copies of a state."""
        if source.n_nodes != self.n_nodes or source.task.mode != self.task.mode:
            raise ValueError(
                f"BallBatch.copy_env: source has {source.n_nodes} nodes in mode {source.task.mode}, "
                f"this batch {self.n_nodes} in mode {self.task.mode}: must be equal"
            )
        rows = np.asarray(rows, dtype=np.int64)
        mine = self.env_arrays()
        for name, array in source.env_arrays().items():
            mine[name][rows] = array[e]

    def close(self) -> None:
        """Stop the step threads (if any)."""
        if self._pool is not None:
            self._pool.shutdown()
            self._pool = None


def guided_chunks(n_envs: int, threads: int) -> list[int]:
    """Boundaries ``[0, b_1, ..., n_envs]`` of the chunks a threaded step hands out, in the order
    they are drawn: each chunk is ``1 / (2 threads)`` of the envs still left (guided scheduling), so
    the first are large (long runs of envs one thread steps in a row) and the last single envs
    (a thread finishing early has small pieces left to take instead of waiting for the other's
    last large one). While at least ``ENVS_PER_LINE`` envs are left, chunks are whole multiples of
    it: the per-env arrays' cache lines are then written by one thread only."""
    bounds = [0]
    while bounds[-1] < n_envs:
        left = n_envs - bounds[-1]
        size = max(1, left // (2 * threads))
        if size >= ENVS_PER_LINE:
            size -= size % ENVS_PER_LINE
        bounds.append(bounds[-1] + size)
    return bounds


def compiled_entry(dispatcher: Any, args: tuple[Any, ...]) -> Callable[..., None]:
    """The compiled entry point of numba ``dispatcher`` for arguments of the types of ``args``
    (compiled, or loaded from the cache, on first use). Calling it skips the dispatcher's typing of
    the arguments: about 13 us per call for the ~100 arrays of a step (7 us are left, for unboxing
    them). The caller must pass arguments of exactly these types (dtype, dimensions, layout)."""
    dispatcher = python_entry(dispatcher)
    signature = tuple(dispatcher.typeof_pyval(a) for a in args)
    if signature not in dispatcher.overloads:
        dispatcher.compile(signature)
    return dispatcher.overloads[signature].entry_point
