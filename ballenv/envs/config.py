"""The keyword arguments of InflatedBall-v3, validated once, and what both envs derive from them:
the physics scene, the task settings, the observation bounds, and the reward and episode end."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, fields
from typing import Any

import numpy as np
from gymnasium.error import ResetNeeded
from numpy.typing import ArrayLike, NDArray

from ballenv.physics.base.layout import STATUS_IMPULSE_AT_DT_MIN, STATUS_STEP_TOO_SMALL
from ballenv.physics.base.ring import burst_pressure, inflation_ratio_of

from ..physics import Ground, Ring, Scene
from ..physics.scene import check_choice, check_real
from . import observation
from .numerics import ENV_FIDELITIES, with_env_fidelity
from .task import END_FAILURE, MODE_PADDLE, MODE_PRESSURE, Task

ACTION_MODES = {"pressure": MODE_PRESSURE, "paddle": MODE_PADDLE}
FAILURES = {
    STATUS_STEP_TOO_SMALL: "rejected steps (Newton failure, energy gain or a self-crossing wall) "
    "halved the step below Scene.dt_min",
    STATUS_IMPULSE_AT_DT_MIN: "the contact impulse stayed above impulse_tol at the smallest step",
}


@dataclass(frozen=True)
class BallEnvConfig:
    """Keyword arguments of InflatedBall-v3 (SI units); see the env's Arguments table."""

    action_mode: str = "pressure"
    fidelity: str = "fast"
    control_frequency: float = 100.0
    target_height_range: tuple[float, float] = (0.5, 1.0)
    start_height_range: tuple[float, float] = (0.6, 1.2)
    pressure_range: tuple[float, float] = (10e3, 50e3)
    initial_pressure: float = 30e3
    pressure_rate: float = 4e5
    paddle_max_impulse: float = 0.15
    paddle_reach: float = 0.4
    paddle_depth: float = 0.06
    paddle_strike_duration: float = 3e-3
    radius: float = 0.12
    youngs_modulus: float = 10e6
    thickness: float = 2e-3
    width: float = 0.02
    density: float = 1100.0
    friction: float = 0.5
    damping: float = 20.0
    gravity: float = 9.81
    reward_margin: float = 0.5
    reset_noise_scale: float = 0.05
    arena_half_width: float = 3.0
    arena_height: float = 5.0
    rest_height: float = 0.01

    def __post_init__(self) -> None:
        o = "InflatedBall-v3"
        s = object.__setattr__
        check_choice(o, "action_mode", self.action_mode, tuple(ACTION_MODES))
        check_choice(o, "fidelity", self.fidelity, tuple(ENV_FIDELITIES))
        s(
            self,
            "control_frequency",
            check_real(o, "control_frequency", self.control_frequency, 1.0, 1e4, "Hz"),
        )
        for name, lo, hi, unit in (
            ("paddle_max_impulse", 0.0, 10.0, "N s"),
            ("pressure_rate", 0.0, 1e12, "Pa/s"),
            ("paddle_reach", 0.0, 10.0, "m"),
            ("paddle_depth", 0.0, 10.0, "m"),
            ("friction", 0.0, 10.0, ""),
            ("damping", 0.0, 1e4, "1/s"),
            ("reset_noise_scale", 0.0, 10.0, "m/s"),
            ("rest_height", 0.0, 1.0, "m"),
        ):
            s(self, name, check_real(o, name, getattr(self, name), lo, hi, unit))
        # a strike fits in one control step; the pressure mode never strikes, so any control rate goes
        paddle = self.action_mode == "paddle"
        longest = self.control_dt if paddle else 1.0
        what = "one control step, 1 / control_frequency" if paddle else "1 s"
        s(
            self,
            "paddle_strike_duration",
            check_real(
                o, "paddle_strike_duration", self.paddle_strike_duration, 0.0, longest, f"s (at most {what})",
                low_open=True,
            ),
        )  # fmt: skip
        margin = check_real(o, "reward_margin", self.reward_margin, 0.0, 100.0, "", low_open=True)
        s(self, "reward_margin", margin)
        s(self, "gravity", check_real(o, "gravity", self.gravity, 0.0, 1000.0, "m/s^2", low_open=True))
        s(self, "arena_half_width", check_real(o, "arena_half_width", self.arena_half_width, 0.1, 1e4, "m"))
        s(self, "arena_height", check_real(o, "arena_height", self.arena_height, 0.1, 1e4, "m"))
        _check_wall(self)
        s(self, "pressure_range", check_range(o, "pressure_range", self.pressure_range, 0.0, 1e8, "Pa"))
        _check_wall_holds(self, "pressure_range", self.pressure_range[1])
        ring = self.ring(self.pressure_range[1])
        s(self, "initial_pressure", check_real(o, "initial_pressure", self.initial_pressure, 0.0, 1e8, "Pa"))
        _check_wall_holds(self, "initial_pressure", self.initial_pressure)
        if self.action_mode == "pressure" and not (
            self.pressure_range[0] <= self.initial_pressure <= self.pressure_range[1]
        ):
            raise ValueError(
                f"{o}.initial_pressure = {self.initial_pressure!r} is out of range: must lie in "
                f"pressure_range = {self.pressure_range} Pa"
            )
        low = 2.0 * ring.radius  # the centre of a resting ball is about one (inflated) radius up
        for name in ("target_height_range", "start_height_range"):
            s(self, name, check_range(o, name, getattr(self, name), low, self.arena_height, "m"))

    @property
    def mode(self) -> int:
        return ACTION_MODES[self.action_mode]

    @property
    def control_dt(self) -> float:
        return 1.0 / self.control_frequency

    @property
    def n_nodes(self) -> int:
        return ENV_FIDELITIES[self.fidelity]["n_nodes"]

    def ring(self, pressure: float | None) -> Ring:
        """The ball as a physics Ring holding gas ``pressure`` (Pa) at rest."""
        return Ring(
            radius=self.radius, n_nodes=self.n_nodes, youngs_modulus=self.youngs_modulus,
            thickness=self.thickness, width=self.width, density=self.density, pressure=pressure,
        )  # fmt: skip

    def scene(self) -> Scene:
        """The physics scene of one env (its ring's state is set at every reset)."""
        base = Scene(
            rings=[self.ring(self.initial_pressure)],
            grounds=[Ground(angle=0.0, height=0.0, friction=self.friction)],
            gravity=self.gravity,
            damping=self.damping,
            self_intersection="reject",  # the env's dynamics: no self-contact barrier
        )
        return with_env_fidelity(base, self.fidelity)

    def task_settings(self) -> dict[str, float]:
        """The scalar fields of ``batch.Task``."""
        return {
            "mode": self.mode,
            "control_dt": self.control_dt,
            "pressure_low": float(self.pressure_range[0]),
            "pressure_high": float(self.pressure_range[1]),
            "pressure_rate": self.pressure_rate,
            "paddle_max_impulse": self.paddle_max_impulse,
            "paddle_reach": self.paddle_reach,
            "paddle_depth": self.paddle_depth,
            "paddle_strike_duration": self.paddle_strike_duration,
            "ground_height": 0.0,
            "gravity": self.gravity,
            "reward_margin": self.reward_margin,
            "arena_half_width": self.arena_half_width,
            "arena_height": self.arena_height,
            "rest_height": self.rest_height,
        }

    def largest_radius(self) -> float:
        """Radius (m) of the inflated circle at the largest pressure the env can set."""
        ea = self.youngs_modulus * self.width * self.thickness
        p = max(self.pressure_range[1], self.initial_pressure)
        return self.radius / (1.0 - inflation_ratio_of(p, self.width, self.radius, self.n_nodes, ea))

    def observation_bounds(self) -> tuple[NDArray[np.float32], NDArray[np.float32]]:
        """(low, high) float32 bounds of the observation vector (``observation.FIELDS``); observations
        are clipped to them."""
        return observation.bounds(self, self.mode == MODE_PADDLE)

    @classmethod
    def from_kwargs(cls, kwargs: Mapping[str, Any]) -> BallEnvConfig:
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(kwargs) - known)
        if unknown:
            raise TypeError(
                f"InflatedBall-v3 got unknown keyword arguments {unknown}; known: {sorted(known)}"
            )
        return cls(**kwargs)


def _check_wall(config: BallEnvConfig) -> None:
    """The ring's own checks of the wall's keywords (``radius``, ``youngs_modulus``, ``thickness``,
    ``width``, ``density``: the same names on the env and on :class:`Ring`), reported as the env's."""
    try:
        config.ring(None)
    except ValueError as err:
        raise ValueError(str(err).replace("Ring.", "InflatedBall-v3.", 1)) from None


def _check_wall_holds(config: BallEnvConfig, name: str, pressure: float) -> None:
    """ValueError naming the keyword ``name`` if ``pressure`` (Pa, gauge, at rest) bursts the ball:
    above the pressure its wall holds stretched by 100 % (``ring.burst_pressure``)."""
    held = burst_pressure(config.radius, config.n_nodes, config.youngs_modulus, config.thickness)
    if pressure > held:
        raise ValueError(
            f"InflatedBall-v3.{name} = {getattr(config, name)!r} is out of range: {pressure:g} Pa must be "
            f"at most {held:.6g} Pa, the gauge pressure that stretches the wall (radius = {config.radius:g} "
            f"m, youngs_modulus = {config.youngs_modulus:g} Pa, thickness = {config.thickness:g} m) by "
            f"100 %; beyond, the ball bursts: lower {name} or stiffen the wall (youngs_modulus, thickness)"
        )


def check_range(owner: str, name: str, value: Any, low: float, high: float, unit: str) -> tuple[float, float]:
    valid = f"a pair (low, high) of finite numbers with {low:g} <= low < high <= {high:g} {unit}"
    try:
        lo, hi = (float(v) for v in value)
    except (TypeError, ValueError):
        raise ValueError(f"{owner}.{name} = {value!r} is out of range: must be {valid}") from None
    if not (math.isfinite(lo) and math.isfinite(hi) and low <= lo < hi <= high):
        raise ValueError(f"{owner}.{name} = {value!r} is out of range: must be {valid}")
    return (lo, hi)


def parse_actions(
    actions: ArrayLike, count: int, what: str, owner: str = "InflatedBall-v3"
) -> NDArray[np.float64]:
    """``actions`` as a float64 array of ``count`` finite numbers (any array of that size of real
    numbers: ints or floats, not bools, strings or complex), else ValueError naming the env
    ``owner`` and ``what``."""
    try:
        a = np.asarray(actions)
    except (TypeError, ValueError):  # ragged nesting
        a = np.asarray(None)
    if a.dtype.kind in "iuf" and a.size == count:
        a = a.astype(np.float64).reshape(-1)
        if np.all(np.isfinite(a)):
            return a
    shape = "(1,)" if count == 1 else f"({count}, 1)"
    raise ValueError(
        f"{owner} {what} = {actions!r} is invalid: must be {count} finite real number"
        f"{'s' if count > 1 else ''} (shape {shape}; values outside [-1, 1] are clipped)"
    )


def check_reset(has_reset: bool, call: str, owner: str = "InflatedBall-v3") -> None:
    """Raise gymnasium's ``ResetNeeded`` if ``call`` ("step", "render", ...) of the env ``owner``
    comes before the first reset: until then the ball has no state."""
    if not has_reset:
        raise ResetNeeded(
            f"{owner} {call}() was called before reset(): call reset() first, which places "
            "the ball and draws the episode's target"
        )


def draw_reset(
    config: BallEnvConfig, rng: np.random.Generator
) -> tuple[tuple[float, float], tuple[float, float], float, float]:
    """Start values of one episode from ``rng``: centre (m), velocity (m/s), phase (rad), target (m)."""
    target = rng.uniform(*config.target_height_range)
    height = rng.uniform(*config.start_height_range)
    vx = rng.uniform(-config.reset_noise_scale, config.reset_noise_scale)
    phase = rng.uniform(0.0, 2.0 * np.pi)
    return (0.0, height), (vx, 0.0), phase, target


def failure_message(task: Task, e: int) -> str:
    """Why env ``e``'s simulator stopped, or "" if it did not."""
    if task.end[e] != END_FAILURE:
        return ""
    return FAILURES.get(int(task.status[e]), "the ball sank below the ground (tunnelling)")
