"""Wrappers an agent may train behind, named in the hyperparameter files by RL Baselines3 Zoo's
``env_wrapper`` key (``agents.wrappers.BallStateObservation``, the ball as a body,
``agents.wrappers.BallShapeObservation``, which adds the ring's low shape modes, or
``agents.wrappers.ResidualPump``, the agent as a correction on the tuned pump); ``agents.train``
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
