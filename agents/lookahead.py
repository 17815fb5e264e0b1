"""Privileged references: the pressure mode's pump timing with the amplitude, and the paddle's strike,
chosen at each bounce by trying candidates on copies of the simulator's exact state.

:class:`LookaheadPump` is not a controller an agent could become: it reads the simulator (it copies
the env's state onto copies of its ball: ``InflatedBallEnv.planning_copies`` and ``copy_state_to``)
and looks one bounce ahead. It bounds what the pump's timing
(:meth:`ballenv.controllers.PressurePump.timed`: ``+u`` on the ground and below the landing height,
``-u`` above) can reach when each bounce's amplitude ``u`` is right; the gap from
it to the scripted pump and to a trained policy is what choosing ``u`` from the observation costs.

At the episode's start and after each flight apex it runs ``candidates`` copies, amplitudes evenly
spaced in ``[-span, span]``, each until its next apex after a landing (at most ``horizon`` control
steps), and keeps the amplitude whose apex is nearest the target, ``|h - h_target| / h_target``
(the evaluation's apex error). :class:`LookaheadPaddle` does the same for the paddle mode's strike
(41 corrections of the scripted paddle's strike, each struck when the ball is in the paddle's reach).
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from numpy.typing import NDArray

from ballenv.controllers import PressurePump
from ballenv.envs.inflated_ball import ball_env

from .config import tuned_heuristic
from .policies import HeuristicPolicy
from .wrappers import AMPLITUDE_SPAN


class Lookahead:
    """One-bounce lookahead on copies of the simulator: at a decision, ``candidates`` copies of the
    env's exact state, each acting with its own candidate value (``values``: ``centre`` plus
    offsets evenly spaced in ``[-span, span]``, in the units :meth:`copy_action` reads) until its
    next apex after a landing (at most ``horizon`` control steps); the value whose apex is nearest
    the target wins. Subclasses say how a copy acts on its value."""

    name = "lookahead"
    mode = ""  # the env's action mode it plays

    def __init__(self, env: gym.Env[Any, Any], span: float, candidates: int, horizon: int) -> None:
        ball = ball_env(env)
        config = ball.config
        if config.action_mode != self.mode:
            raise ValueError(
                f"{type(self).__name__}: action_mode = {config.action_mode!r} is invalid: must be "
                f"{self.mode!r}"
            )
        if not 0.0 < span <= 1.0 or candidates < 2:
            raise ValueError(
                f"{type(self).__name__}: span = {span}, candidates = {candidates} are out of range: "
                "span in (0, 1], candidates >= 2"
            )
        self.structure = ball.observation_structure
        self.ball = ball
        self.copies = ball.planning_copies(candidates)
        self.offsets = np.linspace(-span, span, candidates)
        self.values = self.offsets.copy()  # the last plan's candidates
        self.horizon = horizon
        self.expected_error = np.inf  # the apex error the last plan's copy reached
        # each candidate's signed relative error (h - h_target) / h_target in the last plan (NaN: no apex)
        self.candidate_errors = np.full(candidates, np.nan)

    def reset(self, seed: int) -> None:
        """A new episode (the ``agents.policies.Policy`` protocol)."""
        raise NotImplementedError

    def act(self, obs: NDArray[np.float32]) -> NDArray[np.float32]:
        """The env action for ``obs``, planning where a decision falls."""
        raise NotImplementedError

    def copy_action(self, obs: NDArray[np.float32], value: float) -> float:
        """The env action of a copy observing ``obs`` that plays candidate ``value``."""
        raise NotImplementedError

    def label(self) -> float:
        """The value a policy should learn from the last plan (``agents.imitation``'s label); NaN if
        the plan gives none (the best candidate is then played)."""
        raise NotImplementedError

    def plan(self, centre: float = 0.0) -> float:
        """The value of ``centre + offsets`` whose copy's next apex after a landing is nearest the
        target (the middle candidate if no copy reaches one: the episode ends first); its error in
        ``expected_error``."""
        self.values = values = centre + self.offsets
        copies = self.copies
        self.ball.copy_state_to(copies, np.arange(values.size))
        target = copies.task.target[0]
        signed = np.full(values.size, np.nan)
        landed = np.zeros(values.size, dtype=bool)
        running = np.ones(values.size, dtype=bool)
        actions = np.zeros(values.size)
        for _ in range(self.horizon):
            for i in np.flatnonzero(running):
                actions[i] = self.copy_action(copies.obs[i], values[i])
            copies.step(actions, running)
            landed |= ~copies.task.airborne
            apex = running & landed & (copies.task.apex_count > 0)
            signed[apex] = (copies.task.apex_height[apex] - target) / target
            running &= ~apex & (copies.task.end == 0)
            if not running.any():
                break
        error = np.where(np.isnan(signed), np.inf, np.abs(signed))
        best = int(np.argmin(error)) if np.isfinite(error).any() else values.size // 2
        self.candidate_errors = signed
        self.expected_error = float(error[best])
        return float(values[best])


class LookaheadPump(Lookahead):
    """The pump's timing with each bounce's amplitude chosen by one-bounce lookahead on copies of
    the simulator's state (see the module doc): the candidates (``values``) are amplitudes ``u`` in
    ``[-span, span]``. Pressure mode only."""

    mode = "pressure"

    def __init__(
        self, env: gym.Env[Any, Any], span: float = AMPLITUDE_SPAN, candidates: int = 41, horizon: int = 300
    ) -> None:
        super().__init__(env, span, candidates, horizon)
        landing = tuned_heuristic("pressure").get("landing_height", 0.35)
        self.pump = PressurePump(self.structure, gravity=ball_env(env).config.gravity, landing_height=landing)
        self.amplitude: float | None = None

    def reset(self, seed: int) -> None:
        self.amplitude = None

    def act(self, obs: NDArray[np.float32]) -> NDArray[np.float32]:
        if self.amplitude is None or self.ball.apexes_last_step > 0:
            self.amplitude = self.plan()
        return self.pump.timed(obs, self.amplitude)

    def copy_action(self, obs: NDArray[np.float32], value: float) -> float:
        return float(self.pump.timed(obs, value)[0])

    def label(self) -> float:
        """The amplitude where the candidates' apex errors first cross zero (:func:`zero_crossing`)."""
        return zero_crossing(self.candidate_errors, self.values)[0]


class LookaheadPaddle(Lookahead):
    """The scripted paddle's strike (``PaddleDribble``, tuned) corrected by one-bounce lookahead:
    when the ball is in the paddle's reach, the candidates are that strike's paddle action plus
    offsets in ``[-span, span]`` (``span`` 0.1: 7.5 mN s of impulse either way, about 5 standard
    deviations of the correction the scripted strike needs), each struck at once on its copy, which
    then runs until the apex after the bounce; the strike nearest the target is played. Between
    strikes the paddle is idle. Paddle mode only."""

    mode = "paddle"

    def __init__(
        self, env: gym.Env[Any, Any], span: float = 0.1, candidates: int = 41, horizon: int = 300
    ) -> None:
        super().__init__(env, span, candidates, horizon)
        self.scripted = HeuristicPolicy(env)
        self.in_reach = self.structure["paddle_in_reach"]

    def reset(self, seed: int) -> None:
        self.scripted.reset(seed)

    def reaches(self, obs: NDArray[np.float32]) -> bool:
        return bool(obs[self.in_reach][0] > 0.5)

    def act(self, obs: NDArray[np.float32]) -> NDArray[np.float32]:
        scripted = float(self.scripted.act(obs)[0])
        if not self.reaches(obs):
            return np.array([-1.0], dtype=np.float32)
        return np.array([np.clip(self.plan(scripted), -1.0, 1.0)], dtype=np.float32)

    def copy_action(self, obs: NDArray[np.float32], value: float) -> float:
        """The env's float32 action, as :meth:`act` plays it: a copy's bounce is then the env's."""
        return float(np.float32(np.clip(value, -1.0, 1.0))) if self.reaches(obs) else -1.0

    def label(self) -> float:
        """The root of the trend through the candidates' apex errors (:func:`trend_crossing`): the
        strike the state calls for, without the bounce's scatter between neighbouring strikes."""
        return trend_crossing(self.candidate_errors, self.values)


def lookahead_for(env: gym.Env[Any, Any]) -> Lookahead:
    """The privileged lookahead of ``env``'s action mode, with its default candidates."""
    mode = ball_env(env).config.action_mode
    return next(kind for kind in (LookaheadPump, LookaheadPaddle) if kind.mode == mode)(env)


def zero_crossing(curve: NDArray[np.float64], amplitudes: NDArray[np.float64]) -> tuple[float, float]:
    """Where a plan's signed errors ``curve`` (``LookaheadPump.candidate_errors``) over
    ``amplitudes`` first cross zero upwards, linear between the two candidates around it, and the
    slope there (per unit amplitude, over up to three candidates each side); (NaN, NaN) if they do
    not cross."""
    up = np.flatnonzero((curve[:-1] < 0) & (curve[1:] >= 0))
    if not up.size:
        return np.nan, np.nan
    i = int(up[0])
    step = amplitudes[i + 1] - amplitudes[i]
    crossing = amplitudes[i] - curve[i] * step / (curve[i + 1] - curve[i])
    low, high = max(i - 2, 0), min(i + 3, len(curve) - 1)
    return float(crossing), float((curve[high] - curve[low]) / (amplitudes[high] - amplitudes[low]))


def trend_crossing(curve: NDArray[np.float64], values: NDArray[np.float64]) -> float:
    """Where the least-squares line through a plan's signed errors ``curve`` over ``values`` (the
    candidates that reached an apex) crosses zero, within the candidates' range; NaN if fewer than
    three reached one or the line does not rise. A strike's bounce scatters by 1-2 % of the target
    between candidates 0.4 mN s apart (the ring lands a little later and turned), a scatter no
    observation predicts; the line's root is the strike the state calls for, the first crossing
    of the scattered curve (:func:`zero_crossing`) a draw from that scatter."""
    ok = np.isfinite(curve)
    if ok.sum() < 3:
        return np.nan
    slope, intercept = np.polyfit(values[ok], curve[ok], 1)
    if slope <= 0.0:
        return np.nan
    return float(np.clip(-intercept / slope, values[0], values[-1]))
