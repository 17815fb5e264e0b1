"""The observation vector of InflatedBall3D-v0, declared once.

:data:`FIELDS` lists the entries of every observation in order, :data:`PADDLE_FIELDS` those that
paddle mode appends; each is ``per_vertex * V + fixed`` entries for a ball of V vertices. The
length (:func:`size`), the name -> slice map (:func:`structure`) and the float32 bounds the
observations are clipped to (:func:`bounds`) all derive from the tables.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from ..observation import (
    MAX_NODE_FORCE,
    MAX_PRESSURE,
    MAX_SPEED,
    SUNK_HEIGHT,
    VACUUM_GAUGE_PRESSURE,
    Field,
    Settings,
)

if TYPE_CHECKING:
    from .config import Ball3DConfig


def _reach(c: Settings) -> float:
    return 4.0 * c.largest_radius()


def _centre_low(c: Settings) -> tuple[float, ...]:
    return (-c.arena_half_width, -c.arena_half_width, SUNK_HEIGHT)


def _centre_high(c: Settings) -> tuple[float, ...]:
    return (c.arena_half_width, c.arena_half_width, c.arena_height)


FIELDS = (
    Field("vertex_position", 3, 0, lambda c: -_reach(c), _reach, "m",
          "vertex x, y, z relative to the centre of mass, vertex after vertex"),
    Field("vertex_velocity", 3, 0, lambda c: -MAX_SPEED, lambda c: MAX_SPEED, "m/s",
          "vertex velocity relative to the centre-of-mass velocity"),
    Field("centre_of_mass_position", 0, 3, _centre_low, _centre_high, "m",
          "x, y, and height above the ground"),
    Field("centre_of_mass_velocity", 0, 3, lambda c: -MAX_SPEED, lambda c: MAX_SPEED, "m/s", "vx, vy, vz"),
    Field("ground_normal_force", 1, 0, lambda c: 0.0, lambda c: MAX_NODE_FORCE, "N",
          "each vertex's normal ground reaction (0 in flight)"),
    Field("pressure", 0, 1, lambda c: VACUUM_GAUGE_PRESSURE, lambda c: MAX_PRESSURE, "Pa",
          "gauge pressure of the gas now"),
    Field("pressure_setpoint", 0, 1, lambda c: min(c.pressure_range[0], c.initial_pressure),
          lambda c: max(c.pressure_range[1], c.initial_pressure), "Pa",
          "the gas amount, as gauge pressure at the rest volume (moves toward the command)"),
    Field("target_height", 0, 1, lambda c: c.target_height_range[0], lambda c: c.target_height_range[1], "m",
          "this episode's target apex height of the centre of mass"),
    Field("last_apex", 0, 1, lambda c: SUNK_HEIGHT, lambda c: c.arena_height, "m",
          "height of the centre at its last flight apex (the start height before the first)"),
)  # fmt: skip

PADDLE_FIELDS = (
    Field("target_spot", 0, 2, lambda c: -c.arena_half_width, lambda c: c.arena_half_width, "m",
          "x, y of this episode's target spot on the floor"),
    Field("paddle_height", 0, 1, lambda c: 0.0, lambda c: c.arena_height + _reach(c), "m",
          "the paddle's height (it hovers over the ball)"),
    Field("paddle_in_reach", 0, 1, lambda c: 0.0, lambda c: 1.0, "-",
          "1 if the paddle can strike at the next step (a falling ball in flight, once per flight)"),
    Field("paddle_impulse", 0, 3, lambda c: -c.paddle_max_impulse, lambda c: c.paddle_max_impulse, "N s",
          "impulse the paddle delivered in the last step"),
)  # fmt: skip


def fields(paddle: bool) -> tuple[Field, ...]:
    """The fields in order: :data:`FIELDS`, then :data:`PADDLE_FIELDS` if ``paddle``."""
    return FIELDS + PADDLE_FIELDS if paddle else FIELDS


def size(n_vertices: int, paddle: bool) -> int:
    """Length of the observation vector for a ball of ``n_vertices`` vertices."""
    return sum(f.size(n_vertices) for f in fields(paddle))


def structure(n_vertices: int, paddle: bool) -> dict[str, slice]:
    """Name -> slice of the observation vector for a ball of ``n_vertices`` vertices."""
    out, start = {}, 0
    for f in fields(paddle):
        out[f.name] = slice(start, start + f.size(n_vertices))
        start += f.size(n_vertices)
    return out


def bounds(config: Ball3DConfig) -> tuple[NDArray[np.float32], NDArray[np.float32]]:
    """(low, high) float32 bounds of the observation vector of the env configured by ``config``."""
    n = config.n_vertices
    parts = [
        (np.broadcast_to(np.asarray(f.low(config), dtype=np.float64), (f.size(n),)),
         np.broadcast_to(np.asarray(f.high(config), dtype=np.float64), (f.size(n),)))
        for f in fields(config.paddle)
    ]  # fmt: skip
    low = np.concatenate([p[0] for p in parts]).astype(np.float32)
    high = np.concatenate([p[1] for p in parts]).astype(np.float32)
    return low, high
