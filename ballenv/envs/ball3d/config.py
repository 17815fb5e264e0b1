"""The keyword arguments of InflatedBall3D-v0, validated once, and what the env derives from them:
the simulator's scene and the observation's bounds (SI units)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, fields
from typing import Any

from ...physics.scene import check_choice, check_real
from ...shell import Ground, Scene, Shell
from ...shell.presets import FIDELITY_PRESETS, with_fidelity
from ..config import check_range

ENV_NAME = "InflatedBall3D-v0"
ACTION_MODES = ("pressure", "paddle")


@dataclass(frozen=True)
class Ball3DConfig:
    """Keyword arguments of InflatedBall3D-v0 (SI units); see the env's Arguments table."""

    action_mode: str = "pressure"
    fidelity: str = "fast"
    control_frequency: float = 100.0
    target_height_range: tuple[float, float] = (0.5, 1.0)
    target_spot_radius: float = 0.3
    start_height_range: tuple[float, float] = (0.6, 1.2)
    pressure_range: tuple[float, float] = (20e3, 90e3)
    initial_pressure: float = 55e3
    pressure_rate: float = 4e5
    paddle_max_impulse: float = 1.5
    paddle_max_tilt: float = 0.35
    paddle_reach: float = 0.4
    paddle_depth: float = 0.03
    paddle_strike_duration: float = 3e-3
    radius: float = 0.12
    youngs_modulus: float = 5e6
    poisson_ratio: float = 0.45
    thickness: float = 3e-3
    density: float = 1100.0
    friction: float = 0.5
    damping: float = 20.0
    gravity: float = 9.81
    reward_margin: float = 0.5
    spot_margin: float = 0.3
    reset_noise_scale: float = 0.05
    arena_half_width: float = 2.0
    arena_height: float = 5.0
    rest_height: float = 0.01

    def __post_init__(self) -> None:
        o, s = ENV_NAME, object.__setattr__
        check_choice(o, "action_mode", self.action_mode, ACTION_MODES)
        check_choice(o, "fidelity", self.fidelity, tuple(FIDELITY_PRESETS))
        s(
            self,
            "control_frequency",
            check_real(o, "control_frequency", self.control_frequency, 1.0, 1e4, "Hz"),
        )
        for name, lo, hi, unit in (
            ("target_spot_radius", 0.0, 100.0, "m"),
            ("pressure_rate", 0.0, 1e12, "Pa/s"),
            ("paddle_max_impulse", 0.0, 100.0, "N s"),
            ("paddle_max_tilt", 0.0, 1.2, "rad"),
            ("paddle_reach", 0.0, 10.0, "m"),
            ("paddle_depth", 0.0, 1.0, "m"),
            ("friction", 0.0, 10.0, ""),
            ("damping", 0.0, 1e4, "1/s"),
            ("reset_noise_scale", 0.0, 10.0, "m/s"),
            ("rest_height", 0.0, 1.0, "m"),
        ):
            s(self, name, check_real(o, name, getattr(self, name), lo, hi, unit))
        for name, lo, hi, unit in (
            ("paddle_strike_duration", 0.0, self.control_dt, "s (at most 1 / control_frequency)"),
            ("reward_margin", 0.0, 100.0, ""),
            ("spot_margin", 0.0, 100.0, "m"),
            ("gravity", 0.0, 1000.0, "m/s^2"),
            ("arena_half_width", 0.1, 1e4, "m"),
            ("arena_height", 0.1, 1e4, "m"),
        ):
            s(self, name, check_real(o, name, getattr(self, name), lo, hi, unit, low_open=True))
        self._check_ball()

    def _check_ball(self) -> None:
        """The ball's keywords through :class:`ballenv.shell.Shell`'s checks, named as the env's."""
        o, s = ENV_NAME, object.__setattr__
        s(self, "pressure_range", check_range(o, "pressure_range", self.pressure_range, -5e4, 1e7, "Pa"))
        s(self, "initial_pressure", check_real(o, "initial_pressure", self.initial_pressure, -5e4, 1e7, "Pa"))
        if self.action_mode == "pressure" and not (
            self.pressure_range[0] <= self.initial_pressure <= self.pressure_range[1]
        ):
            raise ValueError(
                f"{o}.initial_pressure = {self.initial_pressure!r} is out of range: must lie in "
                f"pressure_range = {self.pressure_range} Pa"
            )
        try:
            self.shell((0.0, 0.0, 1.0))
        except ValueError as err:
            raise ValueError(str(err).replace("Shell.", f"{o}.", 1)) from None
        low = 2.0 * self.radius  # a resting ball's centre is about one radius up
        for name in ("target_height_range", "start_height_range"):
            s(self, name, check_range(o, name, getattr(self, name), low, self.arena_height, "m"))

    @property
    def paddle(self) -> bool:
        return self.action_mode == "paddle"

    @property
    def control_dt(self) -> float:
        """Control step (s)."""
        return 1.0 / self.control_frequency

    @property
    def n_nodes(self) -> int:
        """The vertex count under the name the observation tables read (``envs.observation.Settings``)."""
        return self.n_vertices

    @property
    def n_vertices(self) -> int:
        """Vertices of the ball's mesh (the fidelity preset's): 10 * 4**k + 2."""
        return 10 * 4 ** FIDELITY_PRESETS[self.fidelity]["subdivisions"] + 2

    def shell(self, position: tuple[float, float, float]) -> Shell:
        """The ball at ``position`` (m), holding ``initial_pressure``."""
        return Shell(
            radius=self.radius, youngs_modulus=self.youngs_modulus, poisson_ratio=self.poisson_ratio,
            thickness=self.thickness, density=self.density, pressure=self.initial_pressure,
            position=position, subdivisions=FIDELITY_PRESETS[self.fidelity]["subdivisions"],
        )  # fmt: skip

    def scene(self) -> Scene:
        """The simulator's scene: the ball over a flat ground at z = 0 with friction, under gravity
        along -z and damping, stepped by the fidelity preset."""
        base = Scene(
            shells=(self.shell((0.0, 0.0, self.start_height_range[1])),),
            grounds=(Ground(friction=self.friction),),
            gravity=self.gravity,
            damping=self.damping,
        )
        return with_fidelity(base, self.fidelity)

    def largest_radius(self) -> float:
        """A bound (m) on the inflated radius: the rest radius stretched by half (beyond, the skin
        of any pressure the env allows has burst its range of validity)."""
        return 1.5 * self.radius

    @classmethod
    def from_kwargs(cls, kwargs: Mapping[str, Any]) -> Ball3DConfig:
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(kwargs) - known)
        if unknown:
            raise TypeError(f"{ENV_NAME} got unknown keyword arguments {unknown}; known: {sorted(known)}")
        return cls(**kwargs)
