"""Wrappers an agent may train behind, named in the hyperparameter files by RL Baselines3 Zoo's
``env_wrapper`` key (``agents.wrappers.BallStateObservation``, the ball as a body,
``agents.wrappers.BallShapeObservation``, which adds the ring's low shape modes,
``agents.wrappers.BallLandingObservation``, which adds where within a control step the ball will
land, or ``agents.wrappers.ResidualPump``, the agent as a correction on the tuned pump); ``agents.train``
applies it to the training and evaluation envs and ``agents.evaluate`` to a saved model's env (a
wrapper with ``action`` and ``restart`` methods also turns the model's actions into the env's and
is restarted at each episode start)."""

from __future__ import annotations

import importlib
from typing import Any, SupportsFloat

import gymnasium as gym
import numpy as np
from numpy.typing import NDArray

from ballenv.envs.inflated_ball import ball_env
from ballenv.envs.observation import MAX_NODE_FORCE, MAX_SPEED

KEPT_FIELDS = (
    "centre_of_mass_position", "centre_of_mass_velocity", "pressure", "pressure_setpoint",
    "target_height", "last_apex", "paddle_height", "paddle_in_reach", "paddle_impulse",
)  # fmt: skip


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
        from ballenv.controllers import PressurePump

        from .baselines import tuned_heuristic

        super().__init__(env)
        config = ball_env(env).config
        if config.action_mode != "pressure":
            raise ValueError(
                f"PumpAmplitude: action_mode = {config.action_mode!r} is invalid: it sets the pump's "
                "amplitude, valid: 'pressure'"
            )
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
                return self.observation(self.raw), total, terminated, truncated, info

    def act(self, observation: NDArray[np.float32], ask: Any) -> NDArray[np.float32]:
        """The env's action for its ``observation``, one env step at a time: at a bounce's start a
        new amplitude from ``ask(wrapped observation) -> action``, then the pump's timing of it."""
        over = self.bounce_over(observation)
        if self.starting or over:
            action = np.asarray(ask(self.observation(observation))).reshape(-1)[0]
            self.amplitude = AMPLITUDE_SPAN * float(np.clip(action, -1.0, 1.0))
        self.starting = False
        return self.pump.timed(observation, self.amplitude)


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
        from .baselines import HeuristicPolicy

        super().__init__(env)
        mode = ball_env(env).config.action_mode
        if mode != "pressure":
            raise ValueError(
                f"ResidualPump: action_mode = {mode!r} is invalid: it corrects the pump, valid: 'pressure'"
            )
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
