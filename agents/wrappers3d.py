"""The 3-D ball's bounce-level task for agents (RL Baselines3 Zoo's ``env_wrapper``
``agents.wrappers3d.PaddleStrike3D``): one agent step a strike, the agent correcting the tuned
scripted dribbler (residual policy learning).

At the control step of a flight where the tuned :class:`ballenv.controllers.PaddleDribble3D` strikes
(the ball in the paddle's reach, ``paddle_in_reach``, and low enough for its strike) it computes its
strike ``b`` (the paddle action: the impulse and the two tilts, each in [-1, 1]); the env's action
is ``clip(b + CORRECTION * a, -1, 1)`` for the agent's action ``a`` in [-1, 1]^3 (``CORRECTION``:
0.05 of the impulse's range, 37.5 mN s at the default 1.5 N s; 0.15 of each tilt's, 0.05 rad at the
default 0.35 rad), and the paddle idles (-1, 0, 0) at every other control step. A zero action is the
dribbler; the agent only learns what its energy balance and constant carry miss (the spin a strike
gives, the mesh's facets at touchdown).

The agent's step runs from one such moment to the next (or the episode's end; a reset idles until
the dribbler's first strike). Its reward is minus the combined error of the first apex after
the strike, as ``agents.evaluate3d`` scores it: ``|h - h_t| / h_t / reward_margin + d / spot_margin``
(``d`` the centre's horizontal distance in m to the target spot at the apex); an episode that ends
early (the ball rests or leaves the arena) costs a missed apex (height error 1) for each flight left
until the time limit, at the distance where it ended. It observes the ball as a body
(:class:`ballenv.envs.ball3d.body.BodyObservation`: centre, velocity, spin, gas, targets, paddle)
and ``b``.
"""

from __future__ import annotations

from typing import Any, SupportsFloat

import gymnasium as gym
import numpy as np
from numpy.typing import NDArray

from ballenv.envs.ball3d.body import BodyObservation
from ballenv.envs.ball3d.env import ball3d_env

from .evaluate import missed_apexes
from .evaluate3d import combined_error, spot_distance
from .policies import Heuristic3DPolicy

# the correction's full range in action units: impulse, x tilt, y tilt
CORRECTION = np.array([0.05, 0.15, 0.15])
IDLE = np.array([-1.0, 0.0, 0.0], dtype=np.float32)  # the paddle's action between strikes
RESET_TRIES = 20  # episodes a reset may start before one reaches a decision


class PaddleStrike3D(BodyObservation):
    """The agent corrects the tuned dribbler's strike once per flight (module doc). 3-D paddle mode
    only. :meth:`act` plays it one env step at a time (``agents.evaluate3d``), asking the model for
    a correction at the same moments."""

    def __init__(self, env: gym.Env[NDArray[np.float32], NDArray[np.float32]]) -> None:
        super().__init__(env)
        inner = ball3d_env(env)
        if not inner.config.paddle:
            raise ValueError(
                "PaddleStrike3D: action_mode = 'pressure' is invalid: it corrects the paddle's strike, "
                "valid: 'paddle' (InflatedBall3DPaddle-v0)"
            )
        self.config = inner.config
        self.scripted = Heuristic3DPolicy(env)
        self.limit = env.spec.max_episode_steps if env.spec and env.spec.max_episode_steps else None
        self.action_space = gym.spaces.Box(-1.0, 1.0, (3,), dtype=np.float32)
        space = self.observation_space
        assert isinstance(space, gym.spaces.Box), space
        self.observation_space = gym.spaces.Box(
            np.concatenate([space.low, -np.ones(3)]).astype(np.float32),
            np.concatenate([space.high, np.ones(3)]).astype(np.float32),
        )
        self.raw = np.zeros(0, dtype=np.float32)
        self.steps = 0
        self.restart()

    def restart(self) -> None:
        """A new episode: the dribbler starts again."""
        self.scripted.reset(0)
        self.base = IDLE.copy()  # the dribbler's strike at the last decision (paddle action)

    def observation(self, observation: NDArray[np.float32]) -> NDArray[np.float32]:
        body = super().observation(observation)
        return np.concatenate([body, self.base]).astype(np.float32)

    def decide(self, observation: NDArray[np.float32]) -> bool:
        """Whether ``observation`` (the env's) is a decision: the ball in reach and the dribbler
        striking (it idles while the ball is too high for its strike); its strike then in ``base``."""
        if observation[self.inner_structure["paddle_in_reach"]][0] <= 0.5:
            return False
        strike = np.asarray(self.scripted.act(observation), dtype=np.float32)
        if strike[0] <= -1.0:
            return False
        self.base = strike
        return True

    def strike(self, action: NDArray[np.float32]) -> NDArray[np.float32]:
        """The env's action of the agent's ``action`` at a decision."""
        a = np.clip(np.asarray(action, dtype=np.float64).reshape(3), -1.0, 1.0)
        return np.clip(self.base + CORRECTION * a, -1.0, 1.0).astype(np.float32)

    def reset(self, **kwargs: Any) -> tuple[NDArray[np.float32], dict[str, Any]]:
        """The env's reset, idling to the first decision; an episode that ends before one (the ball
        too high for the dribbler's strike until the time limit, or at rest) is followed by the
        env's next episode (reset without a seed: the same seed gives the same episodes)."""
        for _ in range(RESET_TRIES):
            self.raw, info = self.env.reset(**kwargs)
            self.restart()
            self.steps, kwargs = 0, {}
            while not self.decide(self.raw):
                self.raw, _, terminated, truncated, info = self.env.step(IDLE)
                self.steps += 1
                if terminated or truncated:
                    break
            else:
                return self.observation(self.raw), info
        raise RuntimeError(
            f"PaddleStrike3D: {RESET_TRIES} episodes in a row ended before the dribbler's first strike "
            "(start heights above the target's reach, or a time limit shorter than the first fall)"
        )

    def step(
        self, action: NDArray[np.float32]
    ) -> tuple[NDArray[np.float32], SupportsFloat, bool, bool, dict[str, Any]]:
        played, apex_error = self.strike(action), None
        while True:
            self.raw, _, terminated, truncated, info = self.env.step(played)
            self.steps += 1
            if apex_error is None and info["apex_count"]:
                apex_error = self.apex_error(info)
            if terminated or truncated or self.decide(self.raw):
                break
            played = IDLE
        cost = 0.0 if apex_error is None else apex_error
        if terminated:
            cost += self.missed(info) * self.apex_error(info, missed=True)
        return self.observation(self.raw), -cost, terminated, truncated, info

    def apex_error(self, info: dict[str, Any], missed: bool = False) -> float:
        """The combined error of the apex of ``info`` (a missed one: height error 1) at the centre's
        present distance to the spot (module doc)."""
        height = 1.0 if missed else abs(info["apex_height"] - info["target_height"]) / info["target_height"]
        return combined_error(self.config, height, spot_distance(self.raw, self.inner_structure))

    def missed(self, info: dict[str, Any]) -> int:
        """The flights left until the time limit when an episode ends early (``agents.evaluate3d``)."""
        if not self.limit:
            return 1
        return missed_apexes(
            self.config, info["target_height"], (self.limit - self.steps) * self.config.control_dt
        )

    def act(self, observation: NDArray[np.float32], ask: Any) -> NDArray[np.float32]:
        """The env's action for its ``observation``, one env step at a time: at a decision the
        dribbler's strike corrected by ``ask(wrapped observation) -> action``, idle otherwise."""
        if not self.decide(observation):
            return IDLE.copy()
        return self.strike(np.asarray(ask(self.observation(observation))))
