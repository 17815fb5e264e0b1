"""Scripted controllers for InflatedBall-v3 and the 3-D ball's InflatedBall3D-v0: the heuristics
that learned policies are measured against.

* the ring's: :class:`PressurePump` and :class:`PaddleDribble`;
* the 3-D ball's: :class:`PressurePump3D` (the pump's rule on the height ``z``) and
  :class:`PaddleDribble3D` (a strike's size from the energy balance, its tilt toward the spot).

All read only the observation (through the env's ``observation_structure``, name -> slice) and keep a
little memory of the current bounce. Call ``reset()`` at each episode start and ``act(obs)`` at each step.
"""

import math
from collections.abc import Mapping

import numpy as np
from numpy.typing import NDArray

from .shell.scene import Shell
from .shell.skin.mesh import icosphere, lumped_masses


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


def shell_mass(shell: Shell) -> float:
    """Mass (kg) of a 3-D ball (``ballenv.shell.Shell``): the lumped masses of its icosphere's skin."""
    mesh = icosphere(shell.subdivisions, shell.radius)
    return float(lumped_masses(mesh, shell.density, shell.thickness).sum())


class PressurePump3D(PressurePump):
    """:class:`PressurePump` for the 3-D ball (InflatedBall3D-v0): the same timing and amplitude
    rule on the centre's height ``z`` (m) and vertical velocity ``v_z`` (m/s) instead of the ring's
    ``y``, ``v_y``. ``landing_height`` (m) is where the falling centre starts the pump stroke."""

    def _read(self, obs: NDArray[np.float32]) -> tuple[float, float, bool, float]:
        com = obs[self.s["centre_of_mass_position"]]
        vel = obs[self.s["centre_of_mass_velocity"]]
        force = float(obs[self.s["ground_normal_force"]].sum())
        target = float(obs[self.s["target_height"]][0])
        return float(com[2]), float(vel[2]), force > 0.0, target


class PaddleDribble3D:
    """Dribble the 3-D ball (InflatedBall3DPaddle-v0) to its target apex and over its target spot,
    with one strike per flight, when the observation says the paddle is in reach.

    Height, from the energy balance: a bounce keeps the fraction ``retention`` of the centre's
    energy above ``rest_height`` (m; the strike's own losses included), so the next apex reaches
    the target ``h_t`` if the ball leaves the strike at height ``z`` falling at ``u`` with
    ``u^2 / 2 + g (z - rest_height) = g (h_t - rest_height) / retention``; the vertical impulse is
    ``J_z = m (u - s)`` for a ball falling at ``s`` now (none if ``u <= s``: the ball is too high).

    Spot, from the flight time: the ball falls for ``t_f`` (from ``z`` at ``u``), touches the ground
    for ``contact_time`` (s) and rises for ``t_r = sqrt(2 (h_t - rest_height) / g)`` to the next
    strike; the bounce's friction keeps the fraction ``carry`` of the horizontal velocity. The
    horizontal velocity that covers ``spot_gain`` times the offset ``d`` (m) to the spot by then is
    ``spot_gain d / (t_f + carry (contact_time + t_r))``; the horizontal impulse ``J_h`` changes the
    present one to it. The tilt from straight down is ``atan(|J_h| / J_z)``, clipped to
    ``max_tilt`` (rad; ``J_h`` shrinks, ``J_z`` stays), toward ``J_h``'s azimuth; the impulse
    ``J = J_z / cos(tilt)`` is clipped to ``max_impulse`` (N s).
    """

    def __init__(
        self,
        structure: Mapping[str, slice],
        mass: float,
        max_impulse: float,
        max_tilt: float,
        gravity: float = 9.81,
        rest_height: float = 0.12,
        retention: float = 0.8,
        carry: float = 0.7,
        spot_gain: float = 1.0,
        contact_time: float = 0.02,
    ) -> None:
        self.s, self.mass, self.g = structure, mass, gravity
        self.max_impulse, self.max_tilt = max_impulse, max_tilt
        self.rest_height, self.retention = rest_height, retention
        self.carry, self.spot_gain, self.contact_time = carry, spot_gain, contact_time

    def reset(self) -> None:
        """A new episode (the controller keeps no memory between steps)."""

    def act(self, obs: NDArray[np.float32]) -> NDArray[np.float32]:
        """The action (3,) float32: idle ``(-1, 0, 0)`` unless the paddle is in reach, else the strike."""
        if obs[self.s["paddle_in_reach"]][0] < 0.5:
            return np.array([-1.0, 0.0, 0.0], dtype=np.float32)
        z = float(obs[self.s["centre_of_mass_position"]][2])
        v = obs[self.s["centre_of_mass_velocity"]].astype(np.float64)
        target = float(obs[self.s["target_height"]][0])
        speed = self.strike_speed(z, target)
        vertical = self.mass * (speed - max(-float(v[2]), 0.0))
        if vertical <= 0.0:
            return np.array([-1.0, 0.0, 0.0], dtype=np.float32)
        offset = obs[self.s["target_spot"]].astype(np.float64) - obs[self.s["centre_of_mass_position"]][:2]
        wanted = self.spot_gain * offset / self.flight_time(z, speed, target)
        return self.action(vertical, self.mass * (wanted - v[:2]))

    def strike_speed(self, z: float, target: float) -> float:
        """The downward speed (m/s) the ball must leave a strike at height ``z`` (m) with for its
        next apex to reach ``target`` (m) (class doc)."""
        r, g = self.rest_height, self.g
        return math.sqrt(max(2.0 * g * ((target - r) / self.retention - (z - r)), 0.0))

    def flight_time(self, z: float, speed: float, target: float) -> float:
        """The time (s) from a strike at height ``z`` (m) leaving at ``speed`` (m/s, down) to the next
        strike at the ``target`` apex (m), horizontal travel after the bounce weighted by ``carry``."""
        r, g = self.rest_height, self.g
        fall = (-speed + math.sqrt(speed * speed + 2.0 * g * max(z - r, 0.0))) / g
        rise = math.sqrt(2.0 * max(target - r, 0.0) / g)
        return max(fall + self.carry * (self.contact_time + rise), 1e-3)

    def action(self, vertical: float, horizontal: NDArray[np.float64]) -> NDArray[np.float32]:
        """The action (3,) float32 of a strike with vertical impulse ``vertical`` (N s, > 0) and
        horizontal impulse ``horizontal`` (2,) N s: the tilt clipped to ``max_tilt``, the impulse to
        ``max_impulse`` (class doc)."""
        tilt = min(math.atan2(float(np.hypot(*horizontal)), vertical), self.max_tilt)
        impulse = min(vertical / math.cos(tilt), self.max_impulse)
        azimuth = math.atan2(float(horizontal[1]), float(horizontal[0]))
        share = tilt / self.max_tilt if self.max_tilt > 0.0 else 0.0
        a = (2.0 * impulse / self.max_impulse - 1.0, share * math.cos(azimuth), share * math.sin(azimuth))
        return np.clip(np.array(a, dtype=np.float32), -1.0, 1.0)
