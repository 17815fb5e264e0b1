"""Wrappers an agent may train behind, named in the hyperparameter files by RL Baselines3 Zoo's
``env_wrapper`` key (``agents.wrappers.BallStateObservation``, the ball as a body,
``agents.wrappers.BallShapeObservation``, which adds the ring's low shape modes,
``agents.wrappers.BallLandingObservation``, which adds where within a control step the ball will
land, ``agents.wrappers.BallRotationObservation``, which adds where its nodes will sit when it lands,
``agents.wrappers.ResidualPump``, the agent as a correction on the tuned pump, or the bounce-level
tasks ``PumpAmplitude``, ``PumpApex`` and ``PaddleStrike``, one agent step a bounce); ``agents.train``
applies it to the training and evaluation envs and ``agents.evaluate`` to a saved model's env (a
wrapper with ``action`` and ``restart`` methods also turns the model's actions into the env's and
is restarted at each episode start)."""

from __future__ import annotations

import importlib
from typing import Any, SupportsFloat

import gymnasium as gym
import numpy as np
from numpy.typing import NDArray

from ballenv.controllers import PressurePump
from ballenv.envs.inflated_ball import ball_env
from ballenv.envs.observation import MAX_NODE_FORCE, MAX_SPEED
from ballenv.envs.task import height_reward

from .config import SUCCESS_TOLERANCE, tuned_heuristic
from .policies import HeuristicPolicy

KEPT_FIELDS = (
    "centre_of_mass_position", "centre_of_mass_velocity", "pressure", "pressure_setpoint",
    "target_height", "last_apex", "paddle_height", "paddle_in_reach", "paddle_impulse",
)  # fmt: skip


def require_mode(env: gym.Env[Any, Any], mode: str, wrapper: str, what: str) -> None:
    """A ``ValueError`` naming ``wrapper`` and ``what`` it does unless ``env`` is in action mode
    ``mode``."""
    got = ball_env(env).config.action_mode
    if got != mode:
        raise ValueError(f"{wrapper}: action_mode = {got!r} is invalid: it {what}, valid: {mode!r}")


class BallStateObservation(
    gym.ObservationWrapper[NDArray[np.float32], NDArray[np.float32], NDArray[np.float32]]
):
    """The ball as a body: the fields of :data:`KEPT_FIELDS` the env has (centre of mass, gas,
    target, last apex, paddle), then the total ground normal force (N) in place of the per-node
    shape. 9 entries in pressure mode, 12 in paddle mode (the env's 5 N + 8 and 5 N + 11). What
    the scripted controllers read; the node states, whose small flight vibrations the running
    normalisation would blow up, are left out."""

    def __init__(self, env: gym.Env[NDArray[np.float32], NDArray[np.float32]]) -> None:
        super().__init__(env)
        structure = ball_env(env).observation_structure
        self.parts = [structure[name] for name in KEPT_FIELDS if name in structure]
        self.force = structure["ground_normal_force"]
        n_nodes = self.force.stop - self.force.start
        space = env.observation_space
        assert isinstance(space, gym.spaces.Box), space  # the env's Box, bounds per entry
        low = np.concatenate([space.low[p] for p in self.parts] + [[0.0]])
        high = np.concatenate([space.high[p] for p in self.parts] + [[n_nodes * MAX_NODE_FORCE]])
        self.observation_space = gym.spaces.Box(low.astype(np.float32), high.astype(np.float32))

    def observation(self, observation: NDArray[np.float32]) -> NDArray[np.float32]:
        kept = [observation[p] for p in self.parts]
        return np.concatenate(kept + [[observation[self.force].sum()]]).astype(np.float32)


SHAPE_MODES = 4  # highest Fourier mode n of the ring's shape observed


class BallShapeObservation(BallStateObservation):
    """The ball as a body (:class:`BallStateObservation`), then the ring's shape as the low Fourier
    modes of its nodes' radial displacement and radial velocity about the centre of mass.

    Node ``i`` at ``p_i`` (m, relative to the centre of mass) with velocity ``v_i`` (m/s, relative
    to the centre of mass's) lies at angle ``theta_i = atan2(p_iy, p_ix)`` (world frame: the ground
    is at ``theta = -pi / 2``), at radial displacement ``d_i = |p_i| - R`` and radial velocity
    ``w_i = v_i . p_i / |p_i|``, with ``R`` the ring's rest radius (m, the env's ``radius``). Over
    the ``N`` nodes, for ``q`` in ``(d, w)`` (:func:`radial_modes`)::

        c_0 = (1 / N) sum_i q_i,   c_n = (2 / N) sum_i q_i cos(n theta_i),
                                   s_n = (2 / N) sum_i q_i sin(n theta_i),   n = 1 .. SHAPE_MODES,

    so ``q_i ~ c_0 + sum_n (c_n cos(n theta_i) + s_n sin(n theta_i))``; a round ring has
    ``c_n = s_n = 0`` for ``n >= 1``. The displacement modes are divided by ``R`` (-), the velocity
    modes by ``R / T`` (-), ``T = 2 pi sqrt(R / g)`` (s) the pendulum period of one radius (about
    0.7 s). Under the retuned ``PressurePump`` the displacement modes stay within 0.03 of their
    means (``c_0`` about 0.19: the gas inflates the ring) and the velocity modes scatter by 0.6
    (``n = 0``) and 1.5 (``c_2``; up to 8 in contact). ``1 + 2 SHAPE_MODES`` entries per quantity:
    9 + 18 = 27 entries in pressure mode, 30 in paddle mode. The modes of a ring of 32 nodes are 18
    smooth numbers where the raw node states are 128 entries, most of them flight vibrations. Like
    its parent it keeps no state between steps: ``agents.evaluate`` calls :meth:`observation` on
    the raw env's observations."""

    def __init__(self, env: gym.Env[NDArray[np.float32], NDArray[np.float32]]) -> None:
        super().__init__(env)
        ball = ball_env(env)
        structure = ball.observation_structure
        self.node_position = structure["node_position"]
        self.node_velocity = structure["node_velocity"]
        config = ball.config
        self.radius = config.radius
        self.speed_scale = self.radius / (2.0 * np.pi * np.sqrt(self.radius / config.gravity))
        low, high = self._shape_bounds(config.largest_radius(), MAX_SPEED)
        space = self.observation_space
        assert isinstance(space, gym.spaces.Box), space
        self.observation_space = gym.spaces.Box(
            np.concatenate([space.low, low]).astype(np.float32),
            np.concatenate([space.high, high]).astype(np.float32),
        )

    def _shape_bounds(
        self, largest_radius: float, max_speed: float
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """(low, high) of the shape entries: a mode is at most twice the largest ``|q_i|``, and a
        node is at most four largest radii (m) from the centre and ``max_speed`` (m/s) from its
        velocity per axis (the env's bounds), so ``|w_i| <= sqrt(2) max_speed``."""
        n = 1 + 2 * SHAPE_MODES
        reach = 2.0 * 4.0 * largest_radius / self.radius
        speed = 2.0 * np.sqrt(2.0) * max_speed / self.speed_scale
        high = np.concatenate([np.full(n, reach), np.full(n, speed)])
        return -high, high

    def observation(self, observation: NDArray[np.float32]) -> NDArray[np.float32]:
        body = super().observation(observation)
        return np.concatenate([body, self.shape_modes(observation)]).astype(np.float32)

    def shape_modes(self, observation: NDArray[np.float32]) -> NDArray[np.float64]:
        """The scaled displacement modes, then the scaled velocity modes (see the class doc)."""
        position = observation[self.node_position].reshape(-1, 2).astype(np.float64)
        velocity = observation[self.node_velocity].reshape(-1, 2).astype(np.float64)
        distance = np.hypot(position[:, 0], position[:, 1])
        angle = np.arctan2(position[:, 1], position[:, 0])
        radial_velocity = np.einsum("ij,ij->i", velocity, position) / np.maximum(distance, 1e-12)
        displacement = radial_modes(distance - self.radius, angle, SHAPE_MODES) / self.radius
        rate = radial_modes(radial_velocity, angle, SHAPE_MODES) / self.speed_scale
        return np.concatenate([displacement, rate])


class BallLandingObservation(BallStateObservation):
    """The ball as a body (:class:`BallStateObservation`), then where within a control step it will
    next land: ``(cos phi, sin phi)`` of :func:`landing_phase` (11 entries in pressure mode, 14 in
    paddle mode).

    The env holds an action over each control step (``control_dt``, 10 ms), so what a pump that
    switches on landing gives a bounce depends on how far into a control step the ball lands. That
    fraction is set by the body's state, but as the fractional part of a fall time of 30-50 control
    steps, a function a small network does not form from height and velocity; here it is given. In
    flight it stays constant (the time to landing falls by one control step per step). Like its
    parent it keeps no state between steps."""

    def __init__(self, env: gym.Env[NDArray[np.float32], NDArray[np.float32]]) -> None:
        super().__init__(env)
        ball = ball_env(env)
        self.structure = ball.observation_structure
        self.control_dt = ball.config.control_dt
        self.gravity = ball.config.gravity
        space = self.observation_space
        assert isinstance(space, gym.spaces.Box), space
        self.observation_space = gym.spaces.Box(
            np.append(space.low, [-1.0, -1.0]).astype(np.float32),
            np.append(space.high, [1.0, 1.0]).astype(np.float32),
        )

    def observation(self, observation: NDArray[np.float32]) -> NDArray[np.float32]:
        phi = landing_phase(observation, self.structure, self.control_dt, self.gravity)
        return np.append(super().observation(observation), [np.cos(phi), np.sin(phi)]).astype(np.float32)


def landing_phase(
    observation: NDArray[np.float32], structure: dict[str, slice], dt: float, g: float
) -> float:
    """Where within its control step of ``dt`` (s) the ball's centre falls to its mean radius above
    the ground, as an angle (rad): ``phi = 2 pi frac(t / dt)`` with the ballistic time to get there
    ``t = (v_y + sqrt(v_y^2 + 2 g (y - r))) / g`` (``y``, ``v_y``: the centre of mass's height, m,
    and vertical velocity, m/s; ``r`` the nodes' mean distance from it, m; ``g``, m/s^2; the root
    taken as 0 below ``r``, in contact)."""
    nodes = observation[structure["node_position"]].reshape(-1, 2).astype(np.float64)
    radius = float(np.sqrt((nodes**2).sum(axis=1)).mean())
    y = float(observation[structure["centre_of_mass_position"]][1])
    vy = float(observation[structure["centre_of_mass_velocity"]][1])
    fall = (vy + np.sqrt(max(vy * vy + 2.0 * g * (y - radius), 0.0))) / g
    return float(2.0 * np.pi * (fall / dt % 1.0))


AMPLITUDE_SPAN = 0.3  # the bounce's amplitude in [-0.3, 0.3]: where the next apex answers it


class PumpAmplitude(BallLandingObservation):
    """The agent sets the tuned pump's amplitude once per bounce: an action ``a`` in [-1, 1] is the
    amplitude ``u = AMPLITUDE_SPAN a``, which the pump's timing (``PressurePump.timed``: ``+u`` on
    the ground and below its landing height, ``-u`` above) plays at every control step until the
    first flight apex after a landing (the observation's ``last_apex`` changes) or the episode's end;
    the agent's step is that whole bounce, its reward the sum of the env's rewards over it. It
    observes the ball as a body with its landing phase (:class:`BallLandingObservation`, 11
    entries). The split is the lookahead's (``agents.lookahead``): the timing scripted, each
    bounce's amplitude chosen. Pressure mode only. An agent's step is about 70 env steps, so a
    budget of env steps is about 70 times its ``n_timesteps``. :meth:`act` plays it one env step at
    a time (``agents.evaluate``): it asks the model for an amplitude when a bounce starts."""

    def __init__(self, env: gym.Env[NDArray[np.float32], NDArray[np.float32]]) -> None:

        super().__init__(env)
        require_mode(env, "pressure", "PumpAmplitude", "sets the pump's amplitude")
        config = ball_env(env).config
        landing = tuned_heuristic("pressure").get("landing_height", 0.35)
        self.pump = PressurePump(self.structure, gravity=config.gravity, landing_height=landing)
        self.action_space = gym.spaces.Box(-1.0, 1.0, (1,), dtype=np.float32)
        self.amplitude = 0.0
        self.raw = np.zeros(0, dtype=np.float32)
        self.restart()

    def restart(self) -> None:
        """A new episode: its first env step starts a bounce."""
        self.landed = False
        self.apex = np.nan
        self.starting = True

    base = 0.0  # the amplitude the agent's zero action plays

    def action_for(self, amplitude: float) -> float:
        """The agent's action that plays the pump's ``amplitude``."""
        return amplitude / AMPLITUDE_SPAN

    def bounce_over(self, observation: NDArray[np.float32]) -> bool:
        """Whether ``observation`` (the env's) ends the bounce: the first flight apex after a landing
        (tracked from the observations passed in, one per env step)."""
        if observation[self.force].sum() > 0.0:
            self.landed = True
        apex = float(observation[self.structure["last_apex"]][0])
        over = self.landed and apex != self.apex
        self.apex = apex
        if over:
            self.landed = False
        return over

    def reset(self, **kwargs: Any) -> tuple[NDArray[np.float32], dict[str, Any]]:
        self.raw, info = self.env.reset(**kwargs)
        self.restart()
        self.bounce_over(self.raw)
        return self.observation(self.raw), info

    def step(
        self, action: NDArray[np.float32]
    ) -> tuple[NDArray[np.float32], SupportsFloat, bool, bool, dict[str, Any]]:
        self.amplitude = AMPLITUDE_SPAN * float(np.clip(np.asarray(action).reshape(-1)[0], -1.0, 1.0))
        total = 0.0
        while True:
            played = self.pump.timed(self.raw, self.amplitude)
            self.raw, reward, terminated, truncated, info = self.env.step(played)
            total += float(reward)
            if terminated or truncated or self.bounce_over(self.raw):
                reward = self.bounce_reward(total, float(reward), terminated, info)
                return self.observation(self.raw), reward, terminated, truncated, info

    def bounce_reward(self, total: float, last: float, terminated: bool, info: dict[str, Any]) -> float:
        """The agent's reward for a bounce: ``total``, the sum of the env's rewards over it (``last``:
        the last of them; ``terminated`` and ``info``: the env's of its last step)."""
        return total

    def act(self, observation: NDArray[np.float32], ask: Any) -> NDArray[np.float32]:
        """The env's action for its ``observation``, one env step at a time: at a bounce's start a
        new amplitude from ``ask(wrapped observation) -> action``, then the pump's timing of it."""
        over = self.bounce_over(observation)
        if self.starting or over:
            action = np.asarray(ask(self.observation(observation))).reshape(-1)[0]
            self.amplitude = AMPLITUDE_SPAN * float(np.clip(action, -1.0, 1.0))
        self.starting = False
        return self.pump.timed(observation, self.amplitude)


class PumpApex(PumpAmplitude):
    """:class:`PumpAmplitude` rewarded by the apex its bounce ends in, :func:`apex_tolerance` (in
    [0, 1]). The sum of the env's rewards over a bounce is mostly its length (38-83 between the 5th
    and 95th percentiles under the lookahead), which the amplitude hardly moves, and the fall's
    share answers the last bounce's apex, not this one's; this reward answers only the bounce's own
    apex, the task's measure, and tells apexes within a few per cent apart."""

    def bounce_reward(self, total: float, last: float, terminated: bool, info: dict[str, Any]) -> float:
        return apex_tolerance(info, last, terminated, ball_env(self.env).config.reward_margin)


ROTATION_HARMONICS = 3  # harmonics of the landing rotation phase observed


def ring_angle(nodes: NDArray[np.float64]) -> float:
    """The ring's rotation (rad) from its nodes' positions ``nodes`` (N, 2) relative to the centre
    of mass (m): the phase of their first Fourier mode, ``arg sum_k z_k exp(-2 pi i k / N)`` with
    ``z_k = x_k + i y_k`` (node 0's angle for a rigid ring; a vibration moves it far less than it
    moves any one node)."""
    z = nodes[:, 0] + 1j * nodes[:, 1]
    return float(np.angle((z * np.exp(-2j * np.pi * np.arange(len(z)) / len(z))).sum()))


def ring_spin(observation: NDArray[np.float32], structure: dict[str, slice]) -> float:
    """The ring's spin ``omega = sum(x v_y - y v_x) / sum(x^2 + y^2)`` (rad/s), node positions and
    velocities relative to the centre of mass's."""
    nodes = observation[structure["node_position"]].reshape(-1, 2).astype(np.float64)
    velocity = observation[structure["node_velocity"]].reshape(-1, 2).astype(np.float64)
    return float((nodes[:, 0] * velocity[:, 1] - nodes[:, 1] * velocity[:, 0]).sum() / (nodes**2).sum())


def phase_harmonics(q: float | NDArray[np.float64]) -> NDArray[np.float64]:
    """``cos 2 pi k q`` and ``sin 2 pi k q`` for ``k = 1 .. ROTATION_HARMONICS``, interleaved along
    the last axis (a phase ``q`` gives 6 numbers, an array of phases one row each)."""
    angle = 2.0 * np.pi * np.asarray(q, dtype=np.float64)
    k = range(1, ROTATION_HARMONICS + 1)
    return np.stack([f(n * angle) for n in k for f in (np.cos, np.sin)], axis=-1)


def rotation_phase(
    observation: NDArray[np.float32], structure: dict[str, slice], g: float, push: float = 0.0
) -> float:
    """Where the ring's nodes will sit when it next lands, in node spacings: ``q = frac(N (theta +
    omega t) / 2 pi)`` in [0, 1), with ``theta`` its :func:`ring_angle` (rad), ``omega = sum(x v_y
    - y v_x) / sum(x^2 + y^2)`` its spin (rad/s; node positions and velocities relative to the
    centre of mass's) and ``t = (v + sqrt(v^2 + 2 g (y - r))) / g`` the ballistic time (s) until
    the centre of mass (height ``y``, vertical velocity ``v = v_y - push``: ``push`` (m/s) a strike
    about to push it down) falls to the nodes' mean distance ``r`` from it above the ground (0 in
    contact). A 32-gon's bounce depends on it: up to 10 % of the rise over half a node spacing
    (``benchmarks/bounce_phase.py``)."""
    nodes = observation[structure["node_position"]].reshape(-1, 2).astype(np.float64)
    y = float(observation[structure["centre_of_mass_position"]][1])
    vy = float(observation[structure["centre_of_mass_velocity"]][1]) - push
    radius = float(np.sqrt((nodes**2).sum(axis=1)).mean())
    spin = ring_spin(observation, structure)
    fall = (vy + np.sqrt(max(vy * vy + 2.0 * g * (y - radius), 0.0))) / g
    return float((len(nodes) * (ring_angle(nodes) + spin * fall) / (2.0 * np.pi)) % 1.0)


class BallRotationObservation(BallStateObservation):
    """The ball as a body (:class:`BallStateObservation`), then where its nodes will sit when it
    next lands: ``cos 2 pi k q`` and ``sin 2 pi k q`` of :func:`rotation_phase` ``q`` for ``k = 1 ..
    ROTATION_HARMONICS`` (15 entries in pressure mode, 18 in paddle mode). What a 32-node ring's
    bounce depends on beyond its body's state: over the scripted paddle's strikes the next apex's
    error scatters by 0.026, of which these harmonics, observed after the strike, leave 0.018
    (``benchmarks/paddle_phase.py``); observed before it they miss the spin the strike gives, which
    :class:`PaddleStrike` observes what sets. Like its parent it keeps no state between steps."""

    def __init__(self, env: gym.Env[NDArray[np.float32], NDArray[np.float32]]) -> None:
        super().__init__(env)
        ball = ball_env(env)
        self.structure = ball.observation_structure
        self.gravity = ball.config.gravity
        space = self.observation_space
        assert isinstance(space, gym.spaces.Box), space
        ones = np.ones(2 * ROTATION_HARMONICS)
        self.observation_space = gym.spaces.Box(
            np.append(space.low, -ones).astype(np.float32), np.append(space.high, ones).astype(np.float32)
        )

    def push(self) -> float:
        """The downward velocity (m/s) a strike about to be made adds to the centre of mass."""
        return 0.0

    def observation(self, observation: NDArray[np.float32]) -> NDArray[np.float32]:
        q = rotation_phase(observation, self.structure, self.gravity, self.push())
        return np.append(super().observation(observation), phase_harmonics(q)).astype(np.float32)


def apex_tolerance(info: dict[str, Any], last: float, terminated: bool, env_margin: float) -> float:
    """A bounce-level agent's reward: DeepMind Control's gaussian tolerance of the relative error
    ``e = |h - h_target| / h_target`` of the apex ``info`` reports, with the evaluation's success
    tolerance as its margin, ``exp(-(s e / 0.05)^2 / 2)`` (``s = sqrt(2 ln 10)``: 0.1 at ``e`` =
    0.05, 0.69 at 0.02, 0.91 at 0.01; the env's own margin, 0.5, gives 0.98 or more below 0.05).
    Without an apex: 0 if the episode ``terminated`` (the ball at rest or out of the arena), else
    the same tolerance of the apex the env's last reward ``last`` rates (its margin ``env_margin``:
    ``last^((env_margin / 0.05)^2)``)."""

    if info.get("apex_count"):
        target = info["target_height"]
        return float(height_reward(abs(info["apex_height"] - target) / target, SUCCESS_TOLERANCE))
    if terminated:
        return 0.0
    return float(last ** ((env_margin / SUCCESS_TOLERANCE) ** 2))


STRIKE_CORRECTION = 0.1  # the agent's full correction of the scripted strike, in paddle action units


class PaddleStrike(BallRotationObservation):
    """The agent corrects the scripted paddle's strike once per flight. At the first step the ball
    is in the paddle's reach (``paddle_in_reach``) the tuned ``PaddleDribble`` computes its strike
    ``b`` (its paddle action, from the energy a bounce keeps); the env's action is ``b +
    STRIKE_CORRECTION a`` (clipped to [-1, 1]; 0.1 is 7.5 mN s of impulse, about 5 standard
    deviations of the correction the lookahead finds) for the agent's action ``a`` in [-1, 1], the
    paddle idle (-1) at every other step. The agent's step runs from one such moment to the next
    (or the episode's end; a reset plays idle until the ball's first fall is in reach, which it is
    for the env's start and target heights), and is rewarded by :func:`apex_tolerance` of the first
    apex after its strike (the bounce it set). It observes the body, the landing rotation phase
    after the scripted strike (:class:`BallRotationObservation`, without the spin the strike gives),
    the ring's rotation phase now (its :func:`phase_harmonics`: which nodes the paddle meets, which
    sets that spin), its spin (rad/s) and ``b`` (26 entries). Residual
    policy learning: a zero action is the scripted paddle, and the agent only has to learn what
    its fixed retention misses.
    Paddle mode only. An agent's step is about 45 env steps. :meth:`act` plays it one env step at a
    time (``agents.evaluate``): it asks the model for a correction at the same moments."""

    def __init__(self, env: gym.Env[NDArray[np.float32], NDArray[np.float32]]) -> None:

        super().__init__(env)
        require_mode(env, "paddle", "PaddleStrike", "corrects the paddle's strike")
        ball = ball_env(env)
        config = ball.config
        self.scripted = HeuristicPolicy(env)
        self.mass = ball.ball_mass
        self.max_impulse = config.paddle_max_impulse
        self.env_margin = config.reward_margin
        self.in_reach = self.structure["paddle_in_reach"]
        self.action_space = gym.spaces.Box(-1.0, 1.0, (1,), dtype=np.float32)
        space = self.observation_space
        assert isinstance(space, gym.spaces.Box), space
        most_spin = 4.0 * MAX_SPEED / config.radius  # rad/s: nodes at half the radius at the largest speed
        ones = np.ones(2 * ROTATION_HARMONICS)
        self.observation_space = gym.spaces.Box(
            np.concatenate([space.low, -ones, [-most_spin, -1.0]]).astype(np.float32),
            np.concatenate([space.high, ones, [most_spin, 1.0]]).astype(np.float32),
        )
        self.raw = np.zeros(0, dtype=np.float32)
        self.restart()

    def restart(self) -> None:
        """A new episode: the scripted paddle starts again."""
        self.scripted.reset(0)
        self.base = -1.0  # the scripted strike at the last decision (paddle action)

    def reaches(self, observation: NDArray[np.float32]) -> bool:
        return bool(observation[self.in_reach][0] > 0.5)

    def push(self) -> float:
        """The scripted strike's push on the centre of mass, ``J / m`` (m/s): the landing rotation
        phase observed is the one the scripted strike leads to."""
        return 0.5 * (self.base + 1.0) * self.max_impulse / self.mass

    def observation(self, observation: NDArray[np.float32]) -> NDArray[np.float32]:
        nodes = observation[self.structure["node_position"]].reshape(-1, 2).astype(np.float64)
        now = phase_harmonics((len(nodes) * ring_angle(nodes) / (2.0 * np.pi)) % 1.0)
        spin = ring_spin(observation, self.structure)
        return np.concatenate([super().observation(observation), now, [spin, self.base]]).astype(np.float32)

    def decide(self, observation: NDArray[np.float32]) -> bool:
        """Feed ``observation`` (the env's) to the scripted paddle; whether it is a decision (the
        ball in reach), its strike then in ``base``."""
        scripted = float(self.scripted.act(observation)[0])
        if self.reaches(observation):
            self.base = scripted
            return True
        return False

    def action_for(self, strike: float) -> float:
        """The agent's action whose env action at this decision is the paddle action ``strike``."""
        return (strike - self.base) / STRIKE_CORRECTION

    def strike(self, action: NDArray[np.float32]) -> NDArray[np.float32]:
        correction = STRIKE_CORRECTION * float(np.clip(np.asarray(action).reshape(-1)[0], -1.0, 1.0))
        return np.array([np.clip(self.base + correction, -1.0, 1.0)], dtype=np.float32)

    def reset(self, **kwargs: Any) -> tuple[NDArray[np.float32], dict[str, Any]]:
        self.raw, info = self.env.reset(**kwargs)
        self.restart()
        while not self.decide(self.raw):
            self.raw, _, terminated, truncated, info = self.env.step(np.array([-1.0], np.float32))
            if terminated or truncated:
                raise RuntimeError(
                    "PaddleStrike: the episode ended before the ball's first fall came in the paddle's "
                    "reach (start and target heights further apart than paddle_reach, or a time limit "
                    "shorter than that fall)"
                )
        return self.observation(self.raw), info

    def step(
        self, action: NDArray[np.float32]
    ) -> tuple[NDArray[np.float32], SupportsFloat, bool, bool, dict[str, Any]]:
        played, apex_info = self.strike(action), None
        while True:
            self.raw, reward, terminated, truncated, info = self.env.step(played)
            if apex_info is None and info["apex_count"]:
                apex_info = info
            if terminated or truncated or self.decide(self.raw):
                break
            played = np.array([-1.0], dtype=np.float32)
        last = (apex_info or info, float(reward), terminated and apex_info is None)
        return self.observation(self.raw), apex_tolerance(*last, self.env_margin), terminated, truncated, info

    def act(self, observation: NDArray[np.float32], ask: Any) -> NDArray[np.float32]:
        """The env's action for its ``observation``, one env step at a time: when the ball is in
        reach, the scripted strike corrected by ``ask(wrapped observation) -> action``; idle
        otherwise."""
        if not self.decide(observation):
            return np.array([-1.0], dtype=np.float32)
        return self.strike(np.asarray(ask(self.observation(observation))))


RESIDUAL_SCALE = 0.1  # the residual's full range, in the env's action units


class ResidualPump(BallStateObservation):
    """The agent as a correction on the tuned ``PressurePump`` (residual policy learning): the env's
    action is ``clip(u_pump + RESIDUAL_SCALE a, -1, 1)``, ``u_pump`` the pump's action for the
    present observation and ``a`` in [-1, 1] the agent's; the agent observes the ball as a body
    (:class:`BallStateObservation`) and ``u_pump`` (10 entries). A zero action is the pump. Pressure
    mode only. It holds the pump's memory of the bounce: :meth:`observation` asks the pump once per
    step, :meth:`action` adds the agent's correction to that answer, :meth:`restart` clears the
    memory at an episode start (``reset`` calls it; ``agents.evaluate`` calls all three on the raw
    env's observations)."""

    def __init__(self, env: gym.Env[NDArray[np.float32], NDArray[np.float32]]) -> None:

        super().__init__(env)
        require_mode(env, "pressure", "ResidualPump", "corrects the pump")
        self.pump = HeuristicPolicy(env).controller
        self.pump_action = np.zeros(1, dtype=np.float32)
        space = self.observation_space
        assert isinstance(space, gym.spaces.Box), space
        self.observation_space = gym.spaces.Box(
            np.append(space.low, -1.0).astype(np.float32), np.append(space.high, 1.0).astype(np.float32)
        )

    def restart(self) -> None:
        """Clear the pump's memory of the bounce (an episode starts)."""
        self.pump.reset()

    def reset(self, **kwargs: Any) -> tuple[NDArray[np.float32], dict[str, Any]]:
        self.restart()
        return super().reset(**kwargs)

    def observation(self, observation: NDArray[np.float32]) -> NDArray[np.float32]:
        self.pump_action = self.pump.act(observation)
        return np.append(super().observation(observation), self.pump_action).astype(np.float32)

    def action(self, action: NDArray[np.float32]) -> NDArray[np.float32]:
        """The env's action: the pump's last answer plus ``RESIDUAL_SCALE`` times ``action``."""
        correction = RESIDUAL_SCALE * np.asarray(action, dtype=np.float32).reshape(1)
        return np.clip(self.pump_action + correction, -1.0, 1.0).astype(np.float32)

    def step(
        self, action: NDArray[np.float32]
    ) -> tuple[NDArray[np.float32], SupportsFloat, bool, bool, dict[str, Any]]:
        return super().step(self.action(action))


def radial_modes(values: NDArray[np.float64], angles: NDArray[np.float64], n_max: int) -> NDArray[np.float64]:
    """Fourier modes of ``values`` (one per node, any unit) at node ``angles`` (rad), for nodes
    spread about evenly around the ring: ``[c_0, c_1, s_1, ..., c_n_max, s_n_max]`` with
    ``c_0 = mean(values)``, ``c_n = (2 / N) sum values cos(n angles)`` and ``s_n = (2 / N) sum
    values sin(n angles)`` (the unit of ``values``)."""
    n = np.arange(1, n_max + 1)[:, None]
    scale = 2.0 / values.size
    cos = scale * (np.cos(n * angles) @ values)
    sin = scale * (np.sin(n * angles) @ values)
    return np.concatenate([[values.mean()], np.column_stack([cos, sin]).ravel()])


def wrapper_class(name: str | None) -> type[gym.ObservationWrapper[Any, Any, Any]] | None:
    """The wrapper class named ``"module.Class"`` (RL Zoo's ``env_wrapper``), or None for None."""
    if not name:
        return None
    module, _, cls = str(name).rpartition(".")
    try:
        return getattr(importlib.import_module(module), cls)
    except (ImportError, AttributeError, ValueError) as exc:
        raise ValueError(f"env_wrapper = {name!r} is not an importable 'module.Class' ({exc})") from None
