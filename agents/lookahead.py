"""A privileged reference for the pressure mode: the pump's timing with the amplitude chosen, at each
bounce, by trying amplitudes on copies of the simulator's exact state.

:class:`LookaheadPump` is not a controller an agent could become: it reads the simulator (it copies
the env's batch, ``ballenv.envs.batch.BallBatch.copy_env``) and looks one bounce ahead. It bounds what
the pump's timing (:meth:`ballenv.controllers.PressurePump.timed`: ``+u`` on the ground and below
the landing height, ``-u`` above) can reach when each bounce's amplitude ``u`` is right; the gap from
it to the scripted pump and to a trained policy is what choosing ``u`` from the observation costs.

At the episode's start and after each flight apex it runs ``candidates`` copies, amplitudes evenly
spaced in ``[-span, span]``, each until its next apex after a landing (at most ``horizon`` control
steps), and keeps the amplitude whose apex is nearest the target, ``|h - h_target| / h_target``
(the evaluation's apex error).
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from numpy.typing import NDArray

from ballenv.controllers import PressurePump
from ballenv.envs.batch import BallBatch
from ballenv.envs.inflated_ball import ball_env

from .baselines import tuned_heuristic


class LookaheadPump:
    """The pump's timing with each bounce's amplitude chosen by one-bounce lookahead on copies of
    the simulator's state (see the module doc). Pressure mode only."""

    name = "lookahead"

    def __init__(
        self, env: gym.Env[Any, Any], span: float = 0.3, candidates: int = 41, horizon: int = 300
    ) -> None:
        ball = ball_env(env)
        config = ball.config
        if config.action_mode != "pressure":
            raise ValueError(
                f"LookaheadPump: action_mode = {config.action_mode!r} is invalid: must be 'pressure'"
            )
        if not 0.0 < span <= 1.0 or candidates < 2:
            raise ValueError(
                f"LookaheadPump: span = {span}, candidates = {candidates} are out of range: "
                "span in (0, 1], candidates >= 2"
            )
        landing = tuned_heuristic("pressure").get("landing_height", 0.35)
        self.pump = PressurePump(ball.observation_structure, gravity=config.gravity, landing_height=landing)
        self.env_batch = ball._batch
        low, high = config.observation_bounds()
        self.copies = BallBatch(config.scene(), candidates, config.task_settings(), low, high)
        self.amplitudes = np.linspace(-span, span, candidates)
        self.horizon = horizon
        self.amplitude: float | None = None
        self.expected_error = np.inf  # the apex error the last plan's copy reached
        # each candidate's signed relative error (h - h_target) / h_target in the last plan (NaN: no apex)
        self.candidate_errors = np.full(candidates, np.nan)

    def reset(self, seed: int) -> None:
        self.amplitude = None

    def act(self, obs: NDArray[np.float32]) -> NDArray[np.float32]:
        if self.amplitude is None or self.env_batch.task.apex_count[0] > 0:
            self.amplitude = self.plan()
        return self.pump.timed(obs, self.amplitude)

    def plan(self) -> float:
        """The amplitude whose copy's next apex after a landing is nearest the target (the middle
        candidate if no copy reaches one: the episode ends first); its error in
        ``expected_error``."""
        copies, amplitudes = self.copies, self.amplitudes
        copies.copy_env(self.env_batch, 0, np.arange(amplitudes.size))
        target = copies.task.target[0]
        signed = np.full(amplitudes.size, np.nan)
        landed = np.zeros(amplitudes.size, dtype=bool)
        running = np.ones(amplitudes.size, dtype=bool)
        actions = np.zeros(amplitudes.size)
        for _ in range(self.horizon):
            for i in np.flatnonzero(running):
                actions[i] = self.pump.timed(copies.obs[i], amplitudes[i])[0]
            copies.step(actions, running)
            landed |= ~copies.task.airborne
            apex = running & landed & (copies.task.apex_count > 0)
            signed[apex] = (copies.task.apex_height[apex] - target) / target
            running &= ~apex & (copies.task.end == 0)
            if not running.any():
                break
        error = np.where(np.isnan(signed), np.inf, np.abs(signed))
        best = int(np.argmin(error)) if np.isfinite(error).any() else amplitudes.size // 2
        self.candidate_errors = signed
        self.expected_error = float(error[best])
        return float(amplitudes[best])
