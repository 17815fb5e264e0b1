"""Many bouncing balls advanced in one compiled call: the physics behind InflatedBall-v3.

Every env holds one ring above one flat ground; the rings share material and numerical settings
and differ in state, gas and target. One :class:`Model` with per-ring arrays of length E holds all
envs; env ``e`` is advanced by the same ``stepper.advance`` as ``simulate()``, on views of its
slices, with its own clock and step size. A batch of E envs therefore gives the same numbers as E
batches of one (the single env is a batch of one).

A control step of env ``e``: start the action (a gas ramp to the new setpoint, or a paddle strike
spread over its duration: ``physics/drive.py``), advance to ``(k + 1) * control_dt`` (the steps
deliver it), and tally the apex events of the interval. Only an apex in flight counts
(after a lift-off, before the next touchdown): the centre of mass also turns round inside a squash.
"""

import math
from collections.abc import Callable, Mapping
from concurrent.futures import ThreadPoolExecutor
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..physics.actuation import (
    hold_gas,
    ramp_rest_pressure,
    rest_circle_radius,
    restart,
    set_gas,
    spread_impulse,
    stop_push,
)
from ..physics.contact import FREE
from ..physics.effects.gas import ring_pressure
from ..physics.geometry import centre_of_mass
from ..physics.integrator import build_solver
from ..physics.jit import kernel, python_entry
from ..physics.layout import (
    CLOCK_H,
    CLOCK_T,
    COUNT_EVENTS,
    COUNT_RECORDS,
    ENERGY_BUDGET,
    ENERGY_FREE,
    ENERGY_TOTAL,
    EVENT,
    EVENT_APEX,
    EVENT_HEIGHT,
    EVENT_KIND,
    EVENT_LIFTOFF,
    EVENT_TOUCHDOWN,
    N_CLOCK,
    N_COUNTERS,
    STATUS_BUFFER_FULL,
    STATUS_DONE,
    Layout,
)
from ..physics.model import (
    PER_RING_FIELDS,
    Model,
    Recording,
    Workspace,
    build_drive,
    build_model,
    build_workspace,
    empty_state,
    rings_view,
)
from ..physics.stepper import advance
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
from .tickets import draw_ticket

if TYPE_CHECKING:
    from ..physics.scene import Scene

MODE_PRESSURE = 0
MODE_PADDLE = 1
END_NONE = 0
END_REST = 1
END_ARENA = 2
END_FAILURE = 3
END_REASONS = ("", "rest", "arena", "sim_failure")
REWARD_TERMS = ("reward_height",)  # the terms' info keys
# columns of Task.reward: the reward, then its terms in the order of REWARD_TERMS
REWARD = Layout("total", *REWARD_TERMS)
REWARD_TOTAL = REWARD.index("total")
REWARD_HEIGHT = REWARD.index("reward_height")
# the tolerance reward is 0.1 at a relative error of reward_margin (DeepMind Control's gaussian)
REWARD_AT_MARGIN = 0.1
REWARD_SCALE = math.sqrt(-2.0 * math.log(REWARD_AT_MARGIN))
NO_OUTPUT = 1e300  # output interval of advance(): record only at the end of the control step
EVENT_ROWS = 32
ENVS_PER_LINE = 8  # envs of a float64 or int64 per-env array in one 64-byte cache line


@kernel(inline="always")
def env_ring():
    """Index of an env's one ring in its model and state views (:func:`env_model`,
    :func:`env_state`): 0, typed int64. Passed as the literal 0, the callees (restart, the energy,
    the forces, ...) would each compile a second time, specialised on that literal."""
    return np.int64(0)


class Task(NamedTuple):
    """The task's settings (scalars) and per-env values (arrays of length E)."""

    mode: int
    control_dt: float  # s
    pressure_low: float  # Pa, gauge pressure at rest for action -1
    pressure_high: float  # Pa, for action +1
    pressure_rate: float  # Pa/s: the gas setpoint moves toward the command at most this fast
    paddle_max_impulse: float  # N s, for action +1 (-1: no strike)
    paddle_reach: float  # m: the paddle strikes when the ball's top is within this of its height
    paddle_depth: float  # m: it touches the nodes within this of the ball's top
    paddle_strike_duration: float  # s: a strike delivers its impulse at a constant rate over this
    ground_height: float  # m
    gravity: float  # m/s^2
    reward_margin: float  # relative apex error at which the reward has fallen to REWARD_AT_MARGIN
    arena_half_width: float  # m
    arena_height: float  # m
    rest_height: float  # m
    target: np.ndarray  # (E,) m, target apex height of the centre of mass
    setpoint: np.ndarray  # (E,) Pa, gas amount as gauge pressure at rest
    rest_radius: np.ndarray  # (E,) m, radius of the inflated circle at the setpoint
    paddle_height: np.ndarray  # (E,) m
    airborne: np.ndarray  # (E,) bool: no ground contact since the last lift-off
    last_apex: np.ndarray  # (E,) m: height of the last flight apex (the start height after a reset)
    steps: np.ndarray  # (E,) int64 control steps taken
    apex_count: np.ndarray  # (E,) int64 flight apexes in the last control step
    apex_error: np.ndarray  # (E,) sum of |h - target| / target over them
    apex_height: np.ndarray  # (E,) m, the last of them (0 if none)
    impulse: np.ndarray  # (E,) N s delivered by the paddle in the last control step
    in_reach: np.ndarray  # (E,) bool: the paddle can strike at the next step (see _paddle_ready)
    struck: np.ndarray  # (E,) bool: the paddle struck since the ball last touched the ground
    status: np.ndarray  # (E,) int64 stepper status of the last control step
    rise: np.ndarray  # (E,) m: height the ball could still rise (free energy over m g)
    reward: np.ndarray  # (E, REWARD.size): the reward and its terms (columns REWARD)
    end: np.ndarray  # (E,) int64: END_NONE, END_REST, END_ARENA or END_FAILURE


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
    task.in_reach[e] = _paddle_ready(task, e, x, v)
    task.status[e] = STATUS_DONE
    task.rise[e] = _rise(me, se, task, e)
    task.reward[e, :] = 0.0
    task.end[e] = END_NONE
    observe_env(model, state, task, e, obs[e])
    _clip(obs[e], low, high, out[e])


@kernel(inline="always")
def _rise(me, se, task, e):
    """Height (m) the ball's centre could still rise: free energy (kinetic, elastic and gas above the
    inflated circle at rest) over ``m g``, plus the centre's height above its resting height."""
    x = se.x[0]
    cy = centre_of_mass(x, se.v[0])[1]
    weight = x.shape[0] * me.node_mass[0] * task.gravity
    return se.energy[0, ENERGY_FREE] / weight + cy - task.ground_height - task.rest_radius[e]


@kernel
def _top(x):
    """Height (m) of the highest node."""
    top = -math.inf
    for i in range(x.shape[0]):
        top = max(top, x[i, 1])
    return top


@kernel(inline="always")
def _paddle_ready(task, e, x, v):
    """Whether the paddle can strike env ``e``'s ball (positions ``x``, velocities ``v``): paddle
    mode, the ball in flight (no ground contact since its last lift-off) and falling (its centre of
    mass moving down) with its top within ``paddle_reach`` of the paddle, and no strike yet in this
    flight (one strike per flight, as a hand dribbles: it meets the ball coming down). Not on the
    ground: a squashing ball's centre still moves down, and a strike there (energy ``v J`` at the
    landing speed ``v``) doubled the bounce's energy for low targets, whose paddle reaches the
    ground."""
    if task.mode != MODE_PADDLE or task.struck[e] or not task.airborne[e]:
        return False
    falling = 0.0
    for i in range(v.shape[0]):
        falling += v[i, 1]
    return falling < 0.0 and abs(_top(x) - task.paddle_height[e]) <= task.paddle_reach


@kernel(inline="always")
def _actuate(me, se, de, task, e, action, t, ws, nodes):
    """Start env ``e``'s actuation of the control step from ``t`` (s), spread over time
    (``physics/drive.py``; the stepper delivers it step by step): in pressure mode the gas ramp from
    the amount held to the setpoint moved toward the command, reached at the control step's end; in
    paddle mode a strike spread over ``paddle_strike_duration`` on the nodes within
    ``paddle_depth`` of the top now."""
    x = se.x[0]
    n = x.shape[0]
    task.impulse[e] = 0.0
    if task.mode == MODE_PRESSURE:
        command = task.pressure_low + 0.5 * (action + 1.0) * (task.pressure_high - task.pressure_low)
        most = task.pressure_rate * task.control_dt
        pressure = task.setpoint[e] + min(most, max(-most, command - task.setpoint[e]))
        if pressure != task.setpoint[e]:
            ramp_rest_pressure(me, de, env_ring(), pressure, t, (task.steps[e] + 1) * task.control_dt, ws)
            task.setpoint[e] = pressure
            task.rest_radius[e] = rest_circle_radius(me, env_ring(), pressure, n)
        return
    impulse = 0.5 * (action + 1.0) * task.paddle_max_impulse
    if not task.in_reach[e] or impulse <= 0.0:
        return
    top = _top(x)
    count = 0
    for i in range(n):
        if x[i, 1] >= top - task.paddle_depth:
            nodes[count] = i
            count += 1
    spread_impulse(de, env_ring(), nodes, count, 0.0, -impulse, t, t + task.paddle_strike_duration)
    task.impulse[e] = impulse
    task.struck[e] = True


@kernel(inline="always")
def _tally(task, e, events, n_events):
    for k in range(n_events):
        kind = int(events[k, EVENT_KIND])
        if kind == EVENT_TOUCHDOWN:
            task.airborne[e] = False
            task.struck[e] = False
        elif kind == EVENT_LIFTOFF:
            task.airborne[e] = True
        elif kind == EVENT_APEX and task.airborne[e]:
            h = events[k, EVENT_HEIGHT] - task.ground_height
            task.apex_count[e] += 1
            task.apex_error[e] += abs(h - task.target[e]) / task.target[e]
            task.apex_height[e] = h
            task.last_apex[e] = h


@kernel(inline="always")
def step_env(
    model, solver, ws, state, trial, drive, clocks, counters, records, events, task, e, action, nodes, obs,
    low, high, out,
):  # fmt: skip
    """One control step of env ``e``: actuate with ``action`` in [-1, 1] (its gas ramp or strike in
    ``drive``), advance to its next control time, tally its flight apexes, then write its
    observation (``obs[e]``, unclipped; ``out[e]``, clipped to ``[low, high]`` as float32) and reward
    and end (``task.reward``, ``task.end``, see :func:`_outcome`). ``ws`` and ``nodes`` are scratch,
    carried over nothing."""
    me = env_model(model, e)
    se = env_state(state, e)
    te = env_state(trial, e)
    de = env_state(drive, e)
    task.apex_count[e] = 0
    task.apex_error[e] = 0.0
    task.apex_height[e] = 0.0
    _actuate(me, se, de, task, e, action, clocks[e, CLOCK_T], ws, nodes)
    t_next = (task.steps[e] + 1) * task.control_dt
    rec = Recording(
        records.t[e], records.x[e], records.v[e], records.pressure[e], records.contact_force[e], events[e]
    )
    counters[e, COUNT_RECORDS] = 0
    while True:
        counters[e, COUNT_EVENTS] = 0
        status = advance(me, solver, ws, se, te, clocks[e], counters[e], t_next, t_next, NO_OUTPUT, rec, de)
        _tally(task, e, events[e], counters[e, COUNT_EVENTS])
        if status != STATUS_BUFFER_FULL:
            break
    task.status[e] = status
    task.steps[e] += 1
    task.rise[e] = _rise(me, se, task, e)
    task.in_reach[e] = _paddle_ready(task, e, se.x[0], se.v[0])
    observe_env(model, state, task, e, obs[e])
    _clip(obs[e], low, high, out[e])
    _outcome(task, e, obs[e], state.x.shape[1])


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
def predicted_apex(task, e, row, n):
    """Height (m) of the flight apex the reward measures, from env ``e``'s observation ``row``: while
    the ball rises in flight, the centre of mass's ballistic apex ``y + v_y^2 / (2 g)`` (exact: only
    gravity acts on the centre); otherwise (falling, or in contact) the last flight apex reached,
    capped by the apex its free energy could still reach, ``r + rise``. So energy a bounce loses
    lowers it at once, and energy put in (a paddle strike, the pump's work ``p dA``) counts from the
    lift-off it leads to: what the next apex will be, not what the energy would give without the
    bounce's loss."""
    cy = row[field_start(OBS_CENTRE_OF_MASS_POSITION, n) + 1]
    vy = row[field_start(OBS_CENTRE_OF_MASS_VELOCITY, n) + 1]
    if task.airborne[e] and vy > 0.0:
        return cy + 0.5 * vy * vy / task.gravity
    return min(task.last_apex[e], task.rest_radius[e] + task.rise[e])


@kernel
def height_reward(error, margin):
    """DeepMind Control's gaussian ``tolerance``: 1 at relative error 0, ``REWARD_AT_MARGIN`` at
    ``margin``, ``exp(-(s error / margin)^2 / 2)`` with ``s = sqrt(-2 ln REWARD_AT_MARGIN)``; in
    (0, 1]."""
    x = REWARD_SCALE * error / margin
    return math.exp(-0.5 * x * x)


@kernel(inline="always")
def _outcome(task, e, row, n):
    """Reward and end of env ``e`` after a control step (see ``InflatedBallEnv``'s Rewards): the
    :func:`height_reward` of the relative error ``|h - h_t| / h_t`` of the :func:`predicted_apex`
    ``h``, 0 once the simulator failed; the episode ends when the ball rests, leaves the arena or
    the simulator fails."""
    centre = field_start(OBS_CENTRE_OF_MASS_POSITION, n)
    cx = row[centre]
    cy = row[centre + 1]
    end = END_NONE
    if task.status[e] != STATUS_DONE or cy < -1.0:
        end = END_FAILURE
    elif abs(cx) > task.arena_half_width or cy > task.arena_height:
        end = END_ARENA
    elif task.rise[e] < task.rest_height:
        end = END_REST
    target = task.target[e]
    height = 0.0
    if end != END_FAILURE:
        height = height_reward(abs(predicted_apex(task, e, row, n) - target) / target, task.reward_margin)
    task.end[e] = end
    task.reward[e, REWARD_TOTAL] = height
    task.reward[e, REWARD_HEIGHT] = height


@kernel
def observe_env(model, state, task, e, row):
    """Write env ``e``'s observation (the fields of ``observation.FIELDS``, unclipped) into ``row``."""
    n = state.x.shape[1]
    nx, ny = model.grounds[0, 0], model.grounds[0, 1]
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
        self.model = _tiled_model(build_model(scene), n_envs)
        self.drive = build_drive(n_envs, self.n_nodes)  # each env's gas ramp and paddle strike
        self.solver = build_solver(scene)
        barrier = bool(self.model.self_barrier)
        self.ws = self._scratch_workspace(barrier)
        self.state = empty_state(n_envs, self.n_nodes)
        self.trial = empty_state(n_envs, self.n_nodes)
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
        self.threads = max(1, min(int(threads), n_envs))
        self._pool: ThreadPoolExecutor | None = None
        # chunk boundaries (one chunk of all envs on one thread) and the counter their numbers are drawn from
        self._chunks = np.array(guided_chunks(n_envs, self.threads) if self.threads > 1 else [0, n_envs])
        self._tickets = np.zeros(1, dtype=np.int64)
        if self.threads > 1:
            self._pool = ThreadPoolExecutor(self.threads - 1, thread_name_prefix="ballenv")
            self._scratch = [(self.ws, self.nodes)] + [
                (self._scratch_workspace(barrier), np.zeros(self.n_nodes, dtype=np.int64))
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
        reset_env(
            self.model, self.solver, self.ws, self.state, self.drive, self.clocks, self.counters, self.task,
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
            self._step(self.ws, self.nodes, actions, active)
            return
        if self._step_batch is None:  # compile or load, once, before the threads call it
            self._step(self.ws, self.nodes, actions, np.zeros_like(active))
            self._tickets[0] = 0
        calls = [self._pool.submit(self._step, ws, nodes, actions, active) for ws, nodes in self._scratch[1:]]
        try:
            self._step(*self._scratch[0], actions, active)
        finally:  # every thread done before this returns or raises
            for call in calls:
                call.result()

    def _step(
        self, ws: Workspace, nodes: NDArray[np.int64], actions: NDArray[np.float64], active: NDArray[np.bool_]
    ) -> None:
        """One :func:`step_batch` call with scratch ``ws``, ``nodes``: the chunks it draws."""
        args = (
            self.model, self.solver, ws, self.state, self.trial, self.drive, self.clocks, self.counters,
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


def _tiled_model(model: Model, n_envs: int) -> Model:
    """``model`` of a one-ring scene with its per-ring arrays repeated for ``n_envs`` envs (the rings
    of different envs never meet: this is not a scene of many rings)."""
    tiled: dict[str, Any] = {
        name: np.repeat(getattr(model, name), n_envs, axis=0) for name in PER_RING_FIELDS
    }
    return model._replace(**tiled)
