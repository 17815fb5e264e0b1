"""The policy interface of every agent here, and the policies that need no training.

A policy is ``reset(seed)`` at an episode start, then ``act(obs) -> action`` (float32 array of shape
(1,)):

* :class:`RandomPolicy`: uniform actions in [-1, 1] from its own seeded generator;
* :class:`HeuristicPolicy`: the scripted controller of the env's action mode
  (:class:`ballenv.controllers.PressurePump` or :class:`ballenv.controllers.PaddleDribble`), with
  the tuned parameters of ``agents/hyperparams/heuristic.yml``.

The privileged lookaheads (:mod:`agents.lookahead`) and saved models (``agents.baselines.ModelPolicy``)
are policies too; ``agents.baselines.make_policy`` makes any of them by name.
"""

from __future__ import annotations

from typing import Any, Protocol

import gymnasium as gym
import numpy as np
from numpy.typing import NDArray

from ballenv.controllers import PaddleDribble, PressurePump
from ballenv.envs.inflated_ball import ball_env

from .config import tuned_heuristic


class Policy(Protocol):
    """What every policy here is: ``reset(seed)`` at an episode start, then ``act(obs)``."""

    name: str

    def reset(self, seed: int) -> None: ...

    def act(self, obs: NDArray[np.float32]) -> NDArray[np.float32]: ...


class RandomPolicy:
    """Uniform random actions; the same seed gives the same actions."""

    name = "random"

    def __init__(self, env: gym.Env[Any, Any]) -> None:
        self.rng = np.random.default_rng(0)

    def reset(self, seed: int) -> None:
        self.rng = np.random.default_rng(seed)

    def act(self, obs: NDArray[np.float32]) -> NDArray[np.float32]:
        return self.rng.uniform(-1.0, 1.0, size=1).astype(np.float32)


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
