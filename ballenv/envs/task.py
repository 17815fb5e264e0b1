"""The task of InflatedBall-v3: its action modes, its reward and its episode ends.

The per-env record :class:`Task` holds the task's settings and each env's progress. In a control
step the batch calls, in order: :func:`actuate` (the action: a gas ramp toward the commanded
setpoint in pressure mode, a strike spread over ``paddle_strike_duration`` in paddle mode),
:func:`tally` (the apex events of the interval: only an apex in flight counts), :func:`rise` (the
height the ball's free energy could still lift it, m) and :func:`outcome` (the reward: DeepMind
Control's gaussian tolerance of the relative error of the :func:`predicted_apex`, and the episode's
end: rest, arena or simulator failure).
"""

import math
from typing import NamedTuple

import numpy as np

from ballenv.physics.base.geometry import centre_of_mass
from ballenv.physics.base.jit import kernel
from ballenv.physics.base.layout import (
    ENERGY_FREE,
    EVENT_APEX,
    EVENT_HEIGHT,
    EVENT_KIND,
    EVENT_LIFTOFF,
    EVENT_TOUCHDOWN,
    STATUS_DONE,
    Layout,
)
from ballenv.physics.step.actuation import ramp_rest_pressure, rest_circle_radius, spread_impulse

from .observation import OBS_CENTRE_OF_MASS_POSITION, OBS_CENTRE_OF_MASS_VELOCITY, field_start

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
    in_reach: np.ndarray  # (E,) bool: the paddle can strike at the next step (see paddle_ready)
    struck: np.ndarray  # (E,) bool: the paddle struck since the ball last touched the ground
    status: np.ndarray  # (E,) int64 stepper status of the last control step
    rise: np.ndarray  # (E,) m: height the ball could still rise (free energy over m g)
    reward: np.ndarray  # (E, REWARD.size): the reward and its terms (columns REWARD)
    end: np.ndarray  # (E,) int64: END_NONE, END_REST, END_ARENA or END_FAILURE


@kernel(inline="always")
def rise(me, se, task, e):
    """Height (m) the ball's centre could still rise: free energy (kinetic, elastic and gas above the
    inflated circle at rest) over ``m g``, plus the centre's height above its resting height."""
    x = se.x[0]
    cy = centre_of_mass(x, se.v[0])[1]
    weight = x.shape[0] * me.node_mass[0] * task.gravity
    return se.energy[0, ENERGY_FREE] / weight + cy - task.ground_height - task.rest_radius[e]


@kernel
def top_height(x):
    """Height (m) of the highest node."""
    top = -math.inf
    for i in range(x.shape[0]):
        top = max(top, x[i, 1])
    return top


@kernel(inline="always")
def paddle_ready(task, e, x, v):
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
    return falling < 0.0 and abs(top_height(x) - task.paddle_height[e]) <= task.paddle_reach


@kernel(inline="always")
def actuate(me, se, de, task, e, action, t, ws, nodes):
    """Start env ``e``'s actuation of the control step from ``t`` (s), spread over time
    (``physics/step/actuation.py``; the stepper delivers it step by step): in pressure mode the gas ramp from
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
    top = top_height(x)
    count = 0
    for i in range(n):
        if x[i, 1] >= top - task.paddle_depth:
            nodes[count] = i
            count += 1
    spread_impulse(de, env_ring(), nodes, count, 0.0, -impulse, t, t + task.paddle_strike_duration)
    task.impulse[e] = impulse
    task.struck[e] = True


@kernel(inline="always")
def tally(task, e, events, n_events):
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
def outcome(task, e, row, n):
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
