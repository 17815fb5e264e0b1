"""Scripted controllers for InflatedBall-v3: the heuristics that learned policies are measured against.

Both read only the observation (through the env's ``observation_structure``, name -> slice) and keep a
little memory of the current bounce. Call ``reset()`` at each episode start and ``act(obs)`` at each step.
"""

from collections.abc import Mapping

import numpy as np
from numpy.typing import NDArray


class _Controller:
    def __init__(self, structure: Mapping[str, slice], gravity: float = 9.81) -> None:
        self.s = structure
        self.g = gravity
        self.reset()

    def reset(self) -> None:
        pass

    def _read(self, obs: NDArray[np.float32]) -> tuple[float, float, bool, float]:
        com = obs[self.s["centre_of_mass_position"]]
        vel = obs[self.s["centre_of_mass_velocity"]]
        force = float(obs[self.s["ground_normal_force"]].sum())
        target = float(obs[self.s["target_height"]][0])
        return float(com[1]), float(vel[1]), force > 0.0, target


class PressurePump(_Controller):
    """Pump gas like a child on a swing: more gas while the ball is on the ground or about to land
    (the re-expanding ball does work ``p dA``), less in flight. The amplitude ``u`` in [-1, 1] is set
    once per bounce, on the way up, from the flight apex ``y + vy^2 / 2g`` it predicts:
    ``u = bias + gain (h_target - apex) / h_target`` (``bias``: the pumping that makes up a bounce's
    loss at the target; negative ``u``, down to ``floor``: the reverse timing takes energy out, gently:
    a ball knocked down to low bounces squashes too little to pump back up)."""

    def __init__(
        self,
        structure: Mapping[str, slice],
        gravity: float = 9.81,
        landing_height: float = 0.35,
        gain: float = 4.0,
        bias: float = 0.7,
        floor: float = 0.0,
    ) -> None:
        super().__init__(structure, gravity)
        self.landing_height = landing_height
        self.gain = gain
        self.bias = bias
        self.floor = floor

    def reset(self) -> None:
        self.amplitude = 1.0

    def act(self, obs: NDArray[np.float32]) -> NDArray[np.float32]:
        y, vy, contact, target = self._read(obs)
        if not contact and vy > 0.0:
            apex = y + vy * vy / (2.0 * self.g)
            self.amplitude = min(1.0, max(self.floor, self.bias + self.gain * (target - apex) / target))
        return self.timed(obs, self.amplitude)

    def timed(self, obs: NDArray[np.float32], amplitude: float) -> NDArray[np.float32]:
        """The pump's timing of amplitude ``amplitude``: the action ``+amplitude`` while the ball is
        on the ground or falls below ``landing_height``, ``-amplitude`` otherwise."""
        y, vy, contact, _ = self._read(obs)
        landing = contact or (vy < 0.0 and y < self.landing_height)
        return np.array([amplitude if landing else -amplitude], dtype=np.float32)


class PaddleDribble(_Controller):
    """Strike the ball once per flight as it falls through the paddle's reach, with the impulse
    that restores the energy of a bounce to the target: a ball of mass ``m`` falling at ``v`` gains
    ``v J + J^2 / 2m`` from an impulse ``J``; it needs ``m g (h_target - r) / retention - m g (apex -
    r)``, ``retention`` being the fraction of its energy a bounce keeps. The apex is the one it saw
    the ball rise to, before the first the start height (``last_apex``): a ball dropped from below
    the paddle's reach after one bounce must be struck on its first fall or it comes to rest."""

    def __init__(
        self,
        structure: Mapping[str, slice],
        mass: float,
        gravity: float = 9.81,
        retention: float = 0.7,
        max_impulse: float = 0.15,
    ) -> None:
        super().__init__(structure, gravity)
        self.mass = mass
        self.retention = retention
        self.max_impulse = max_impulse

    def reset(self) -> None:
        self.apex: float | None = None
        self.struck = False

    def act(self, obs: NDArray[np.float32]) -> NDArray[np.float32]:
        y, vy, contact, target = self._read(obs)
        idle = np.array([-1.0], dtype=np.float32)
        if contact:
            self.struck = False
            return idle
        if vy > 0.0:
            self.apex = y + vy * vy / (2.0 * self.g)
            return idle
        if self.apex is None:  # the first fall, from the start height (rest): no apex seen yet
            self.apex = float(obs[self.s["last_apex"]][0])
        in_reach = obs[self.s["paddle_in_reach"]][0] > 0.5
        if self.struck or not in_reach:
            return idle
        self.struck = True
        m, g = self.mass, self.g
        radius = float(np.abs(obs[self.s["node_position"]][1::2]).max())
        needed = m * g * ((target - radius) / self.retention - (self.apex - radius))
        if needed <= 0.0:
            return idle
        speed = -vy
        impulse = m * (-speed + np.sqrt(speed * speed + 2.0 * needed / m))
        return np.array([min(1.0, 2.0 * impulse / self.max_impulse - 1.0)], dtype=np.float32)
