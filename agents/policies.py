"""The policy interface of every agent here, and the policies that need no training.

A policy is ``reset(seed)`` at an episode start, then ``act(obs) -> action`` (float32 array of the
env's action shape):

* :class:`RandomPolicy`: uniform actions in [-1, 1] from its own seeded generator;
* :class:`HeuristicPolicy`: the scripted controller of the env's action mode
  (:class:`ballenv.controllers.PressurePump` or :class:`ballenv.controllers.PaddleDribble`), with
  the tuned parameters of ``agents/hyperparams/heuristic.yml``;
* for the 3-D ball (InflatedBall3D-v0): :class:`Heuristic3DPolicy`
  (:class:`ballenv.controllers.PressurePump3D` or :class:`ballenv.controllers.PaddleDribble3D`),
  and :class:`IdlePolicy` (the paddle never strikes; the gas stays at its initial amount).

The privileged lookaheads (:mod:`agents.lookahead`) and saved models (``agents.baselines.ModelPolicy``)
are policies too; ``agents.baselines.make_policy`` makes any of them by name.
"""

from __future__ import annotations

from typing import Any, Protocol

import gymnasium as gym
import numpy as np
from numpy.typing import NDArray

from ballenv.controllers import PaddleDribble, PaddleDribble3D, PressurePump, PressurePump3D, shell_mass
from ballenv.envs.ball3d.env import ball3d_env
from ballenv.envs.inflated_ball import ball_env

from .config import tuned_heuristic, tuned_heuristic3d


class Policy(Protocol):
    """What every policy here is: ``reset(seed)`` at an episode start, then ``act(obs)``."""

    name: str

    def reset(self, seed: int) -> None: ...

    def act(self, obs: NDArray[np.float32]) -> NDArray[np.float32]: ...


class RandomPolicy:
    """Uniform random actions of the env's action shape; the same seed gives the same actions."""

    name = "random"

    def __init__(self, env: gym.Env[Any, Any]) -> None:
        self.rng = np.random.default_rng(0)
        self.shape = env.action_space.shape or (1,)

    def reset(self, seed: int) -> None:
        self.rng = np.random.default_rng(seed)

    def act(self, obs: NDArray[np.float32]) -> NDArray[np.float32]:
        return self.rng.uniform(-1.0, 1.0, size=self.shape).astype(np.float32)


class HeuristicPolicy:
    """The scripted controller of the env's action mode (pressure pumping or paddle dribbling), with
    the parameters ``params`` (default: the tuned ones of ``hyperparams/heuristic.yml`` for the env's
    id, see ``agents.tune``; the controller's own defaults where the file has no entry)."""

    name = "heuristic"

    def __init__(self, env: gym.Env[Any, Any], params: dict[str, float] | None = None) -> None:
        ball = ball_env(env)
        config, structure = ball.config, ball.observation_structure
        params = tuned_heuristic(config.action_mode) if params is None else dict(params)
        self.controller: PressurePump | PaddleDribble
        if config.action_mode == "pressure":
            self.controller = PressurePump(structure, gravity=config.gravity, **params)
        else:
            self.controller = PaddleDribble(
                structure,
                ball.ball_mass,
                gravity=config.gravity,
                max_impulse=config.paddle_max_impulse,
                **params,
            )

    def reset(self, seed: int) -> None:
        self.controller.reset()

    def act(self, obs: NDArray[np.float32]) -> NDArray[np.float32]:
        return self.controller.act(obs)


class IdlePolicy:
    """The 3-D ball left alone: in paddle mode the paddle never strikes (action ``(-1, 0, 0)``), in
    pressure mode the gas stays at the env's ``initial_pressure``."""

    name = "no strike"

    def __init__(self, env: gym.Env[Any, Any]) -> None:
        config = ball3d_env(env).config
        low, high = config.pressure_range
        hold = 2.0 * (config.initial_pressure - low) / (high - low) - 1.0 if high > low else 0.0
        self.action = np.array([-1.0, 0.0, 0.0] if config.paddle else [hold], dtype=np.float32)
        self.name = "no strike" if config.paddle else "constant gas"

    def reset(self, seed: int) -> None:
        pass

    def act(self, obs: NDArray[np.float32]) -> NDArray[np.float32]:
        return self.action.copy()


class Heuristic3DPolicy:
    """The 3-D ball's scripted controller of the env's action mode (pumping or dribbling), with the
    parameters ``params`` (default: the tuned ones of ``hyperparams/heuristic.yml`` under the 3-D
    env id; the controller's own defaults where the file has no entry)."""

    name = "dribbler"

    def __init__(self, env: gym.Env[Any, Any], params: dict[str, float] | None = None) -> None:
        ball = ball3d_env(env)
        config, structure = ball.config, ball.observation_structure
        params = tuned_heuristic3d(config.action_mode) if params is None else dict(params)
        self.controller: PressurePump3D | PaddleDribble3D
        if config.paddle:
            self.controller = PaddleDribble3D(
                structure, shell_mass(config.shell((0.0, 0.0, 1.0))), config.paddle_max_impulse,
                config.paddle_max_tilt, gravity=config.gravity, rest_height=config.radius, **params,
            )  # fmt: skip
        else:
            self.controller = PressurePump3D(structure, gravity=config.gravity, **params)
            self.name = "pump"

    def reset(self, seed: int) -> None:
        self.controller.reset()

    def act(self, obs: NDArray[np.float32]) -> NDArray[np.float32]:
        return self.controller.act(obs)
