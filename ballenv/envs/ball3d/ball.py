"""The ball of one InflatedBall3D env: its simulator run and the task's state (targets, flights,
apexes, the paddle, reward and end), stepped one control step at a time (SI units; the rules are
in task.py)."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from ...shell import equilibrium
from ...shell.simulation import SimulationError
from ...shell.steering import Simulation
from . import task
from .config import Ball3DConfig
from .observation import bounds, structure

F64 = NDArray[np.float64]


def random_rotation(rng: np.random.Generator) -> F64:
    """A uniformly random rotation matrix (3, 3): the Q factor of a Gaussian matrix, signs fixed."""
    q, r = np.linalg.qr(rng.standard_normal((3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0.0 else -q


class Ball:
    """One env's ball and task state (module doc)."""

    def __init__(self, config: Ball3DConfig) -> None:
        self.config = config
        self.scene = config.scene()
        shell = self.scene.shells[0]
        x = equilibrium(
            shell, gas_exponent=self.scene.gas_exponent, atmospheric_pressure=self.scene.atmospheric_pressure
        ).x
        self.rest_shape = x - x.mean(axis=0)  # (V, 3) m, at initial_pressure, centred
        self.radius = float(np.linalg.norm(self.rest_shape, axis=1).mean())  # m
        low, high = config.pressure_range if not config.paddle else (config.initial_pressure,) * 2
        self.rest = task.RestEnergy(
            shell, self.scene.gas_exponent, self.scene.atmospheric_pressure, low, high
        )
        self.structure = structure(config.n_vertices, config.paddle)
        self.low, self.high = bounds(config)
        self.sim: Simulation | None = None
        self.target, self.spot = 0.0, np.zeros(2)
        self.setpoint, self.steps = config.initial_pressure, 0
        self.airborne, self.struck, self.in_reach = True, False, False
        self.last_apex, self.apex_count, self.apex_height = 0.0, 0, 0.0
        self.impulse = np.zeros(3)
        self.reward = (0.0, 0.0, 0.0)
        self.end, self.failure, self.seen_events = "", "", 0
        self.obs = np.zeros(len(self.low), dtype=np.float32)

    def reset(self, rng: np.random.Generator) -> None:
        """A new episode from ``rng`` (the env's Starting State)."""
        c = self.config
        self.target = float(rng.uniform(*c.target_height_range))
        height = float(rng.uniform(*c.start_height_range))
        velocity = np.append(rng.uniform(-c.reset_noise_scale, c.reset_noise_scale, 2), 0.0)
        rho, phi = c.target_spot_radius * math.sqrt(rng.uniform()), rng.uniform(0.0, 2.0 * math.pi)
        self.spot = np.array([rho * math.cos(phi), rho * math.sin(phi)])
        x0 = self.rest_shape @ random_rotation(rng).T + np.array([0.0, 0.0, height])
        v0 = np.broadcast_to(velocity, x0.shape)
        self.sim = Simulation(self.scene, x0[None], v0[None], record=False)
        self.setpoint, self.steps = c.initial_pressure, 0
        self.airborne, self.struck, self.in_reach = True, False, False
        self.last_apex, self.apex_count, self.apex_height = height, 0, 0.0
        self.impulse = np.zeros(3)
        self.end, self.failure, self.seen_events = "", "", 0
        self._assess()

    def act(self, action: F64) -> None:
        """One control step of ``action`` (clipped to [-1, 1]) unless the episode has ended; a
        simulator failure ends it (:meth:`fail`) instead of raising."""
        if self.end:
            return
        try:
            self.step(action)
        except (SimulationError, FloatingPointError, np.linalg.LinAlgError) as err:
            self.fail(str(err))

    def step(self, action: F64) -> None:
        """One control step of ``action`` (clipped to [-1, 1])."""
        sim, c = self._sim(), self.config
        t1 = (self.steps + 1) * c.control_dt
        self.impulse = np.zeros(3)
        if not c.paddle:
            command = c.pressure_range[0] + 0.5 * (action[0] + 1.0) * (
                c.pressure_range[1] - c.pressure_range[0]
            )
            most = c.pressure_rate * c.control_dt
            self.setpoint += min(most, max(-most, command - self.setpoint))
            sim.ramp_rest_pressure(0, self.setpoint, t1)
        elif self.in_reach and action[0] > -1.0:
            self._strike(sim, action)
        sim.advance(t1)
        self.steps += 1
        self._tally(sim)
        self._assess()

    def _strike(self, sim: Simulation, action: F64) -> None:
        """The paddle's strike of ``action`` at the control step's start (task.py)."""
        c = self.config
        impulse = 0.5 * (action[0] + 1.0) * c.paddle_max_impulse
        direction = task.strike_direction(c, float(action[1]), float(action[2]))
        x = sim.x[0]
        sim.set_forces(0, task.strike_forces(x, direction, impulse, c.paddle_depth, c.paddle_strike_duration))
        sim.advance(sim.t + c.paddle_strike_duration)
        sim.set_forces(0, np.zeros_like(x))
        self.impulse, self.struck = impulse * direction, True

    def _tally(self, sim: Simulation) -> None:
        """The flights' events of the control step just taken: apexes in flight, lift-offs, touchdowns."""
        events = sim.run.events
        self.apex_count = 0
        for _, _, kind, z in events[self.seen_events :]:
            if kind == "apex" and self.airborne:
                self.last_apex, self.apex_height = z, z
                self.apex_count += 1
            elif kind == "touchdown":
                self.airborne, self.struck = False, False
            elif kind == "liftoff":
                self.airborne = True
        self.seen_events = len(events)

    def _assess(self) -> None:
        """Observation, paddle readiness, reward and end after a reset or a step."""
        sim, c = self._sim(), self.config
        x, v = sim.x[0], sim.v[0]
        if not (np.all(np.isfinite(x)) and np.all(np.isfinite(v))):
            self.fail("the simulator returned a non-finite state")
            return
        mass = sim.run.steps[0].problem.model.mass
        centre, velocity = mass @ x / mass.sum(), mass @ v / mass.sum()
        paddle_height = self.target + self.radius
        self.in_reach = bool(
            c.paddle and self.airborne and velocity[2] < 0.0 and not self.struck
            and x[:, 2].max() >= paddle_height - c.paddle_reach
        )  # fmt: skip
        self._observe(sim, centre, velocity, paddle_height)
        rise, radius = task.rise(sim, self.rest, c.gravity)
        apex = task.predicted_apex(
            self.airborne, centre[2], velocity[2], c.gravity, self.last_apex, radius + rise
        )
        self.reward = task.reward(c, apex, self.target, float(np.hypot(*(centre[:2] - self.spot))))
        if max(abs(centre[0]), abs(centre[1])) > c.arena_half_width or centre[2] > c.arena_height:
            self.end = "arena"
        elif rise < c.rest_height:
            self.end = "rest"

    def _observe(self, sim: Simulation, centre: F64, velocity: F64, paddle_height: float) -> None:
        """The observation vector (observation.py), clipped to its bounds."""
        x, v, s = sim.x[0], sim.v[0], self.structure
        obs = np.empty(len(self.low))
        obs[s["vertex_position"]] = (x - centre).ravel()
        obs[s["vertex_velocity"]] = (v - velocity).ravel()
        obs[s["centre_of_mass_position"]] = centre
        obs[s["centre_of_mass_velocity"]] = velocity
        obs[s["ground_normal_force"]] = np.maximum(sim.contact_force[0, :, 2], 0.0)
        obs[s["pressure"]] = sim.gauge_pressure(0)
        obs[s["pressure_setpoint"]] = self.setpoint
        obs[s["target_height"]] = self.target
        obs[s["last_apex"]] = self.last_apex
        if self.config.paddle:
            obs[s["target_spot"]] = self.spot
            obs[s["paddle_height"]] = paddle_height
            obs[s["paddle_in_reach"]] = float(self.in_reach)
            obs[s["paddle_impulse"]] = self.impulse
        self.obs = np.clip(obs, self.low, self.high).astype(np.float32)

    def fail(self, reason: str) -> None:
        """Ends the episode on a simulator failure; the observation stays the last accepted state's."""
        self.end, self.failure, self.reward = "sim_failure", reason, (0.0, 0.0, 0.0)

    def observe(self) -> NDArray[np.float32]:
        """The observation (a new array)."""
        return self.obs.copy()

    def info(self) -> dict[str, object]:
        """The step's ``info`` (the env's docstring)."""
        return {
            "reward_height": self.reward[1],
            "reward_spot": self.reward[2],
            "time": self.steps * self.config.control_dt,
            "apex_count": self.apex_count,
            "apex_height": self.apex_height,
            "target_height": self.target,
            "target_spot": self.spot.copy(),
            "pressure_setpoint": float(self.setpoint),
            "paddle_impulse": self.impulse.copy(),
            "termination": self.end,
            "sim_failure": self.end == "sim_failure",
            "sim_failure_reason": self.failure,
        }

    def _sim(self) -> Simulation:
        if self.sim is None:
            raise RuntimeError("the ball has no simulation before its first reset")
        return self.sim
