"""The observation vector of InflatedBall-v3, declared once.

:data:`FIELDS` lists the entries of every observation in order, :data:`PADDLE_FIELDS` those that
paddle mode appends. Everything else is derived from these two tables: the length of the vector
(:func:`size`), the name -> slice map (:func:`structure`), the float32 bounds the observations are
clipped to (:func:`bounds`), and the start of each field for the compiled code that writes and reads
observations (``OBS_*`` and :func:`field_start`: ``row[field_start(OBS_PRESSURE, n)]``).

The ``OBS_*`` constants are frozen into the compiled code of ``batch.py``; numba's cache is keyed on
every source file of the package (``ballenv.physics.base.cache_location``), so a changed table is
compiled afresh.
"""

from collections.abc import Callable
from typing import NamedTuple, Protocol

import numpy as np
from numpy.typing import NDArray

from ballenv.physics.base.jit import kernel


class Settings(Protocol):
    """What the observation's bounds read of an env's settings (``config.BallEnvConfig`` is one)."""

    @property
    def n_nodes(self) -> int: ...

    @property
    def arena_half_width(self) -> float: ...  # m

    @property
    def arena_height(self) -> float: ...  # m

    @property
    def initial_pressure(self) -> float: ...  # Pa

    @property
    def pressure_range(self) -> tuple[float, float]: ...  # Pa

    @property
    def target_height_range(self) -> tuple[float, float]: ...  # m

    @property
    def paddle_max_impulse(self) -> float: ...  # N s

    def largest_radius(self) -> float: ...  # m


Bound = Callable[[Settings], "float | tuple[float, ...]"]  # config -> a number, or one per entry

MAX_SPEED = 100.0  # m/s, bound of the velocity observations
MAX_NODE_FORCE = 1e5  # N, bound of the per-node ground normal force observation
MAX_PRESSURE = 1e7  # Pa, upper bound of the pressure observation
VACUUM_GAUGE_PRESSURE = -101325.0  # Pa, lower bound of the pressure observation (no gas at all)
SUNK_HEIGHT = -1.0  # m, lowest centre-of-mass height observed (the simulator has failed below it)


class Field(NamedTuple):
    """One named part of the observation vector: ``per_node * N + fixed`` entries for a ring of N
    nodes, bounded by ``low(config)`` and ``high(config)`` (a number, or one per entry) in ``unit``;
    ``config`` is the env's settings (:class:`Settings`)."""

    name: str
    per_node: int
    fixed: int
    low: Bound
    high: Bound
    unit: str
    description: str

    def size(self, n_nodes: int) -> int:
        """Number of entries for a ring of ``n_nodes`` nodes."""
        return self.per_node * n_nodes + self.fixed


def _node_reach(config: Settings) -> float:
    """Farthest a node can be from the centre of mass (m): four times the largest inflated radius."""
    return 4.0 * config.largest_radius()


FIELDS = (
    Field(
        "node_position", 2, 0, lambda c: -_node_reach(c), _node_reach, "m",
        "node x, y relative to the centre of mass, interleaved",
    ),
    Field(
        "node_velocity", 2, 0, lambda c: -MAX_SPEED, lambda c: MAX_SPEED, "m/s",
        "node velocity relative to the centre-of-mass velocity",
    ),
    Field(
        "centre_of_mass_position", 0, 2, lambda c: (-c.arena_half_width, SUNK_HEIGHT),
        lambda c: (c.arena_half_width, c.arena_height), "m", "x, and height above the ground",
    ),
    Field("centre_of_mass_velocity", 0, 2, lambda c: -MAX_SPEED, lambda c: MAX_SPEED, "m/s", "vx, vy"),
    Field(
        "ground_normal_force", 1, 0, lambda c: 0.0, lambda c: MAX_NODE_FORCE, "N",
        "each node's normal ground reaction (0 in flight)",
    ),
    Field(
        "pressure", 0, 1, lambda c: VACUUM_GAUGE_PRESSURE, lambda c: MAX_PRESSURE, "Pa",
        "current gauge pressure of the gas",
    ),
    Field(
        "pressure_setpoint", 0, 1, lambda c: min(c.pressure_range[0], c.initial_pressure),
        lambda c: max(c.pressure_range[1], c.initial_pressure), "Pa",
        "the gas amount as gauge pressure at rest (moves toward the command)",
    ),
    Field(
        "target_height", 0, 1, lambda c: c.target_height_range[0], lambda c: c.target_height_range[1], "m",
        "this episode's target apex height of the centre of mass",
    ),
    Field(
        "last_apex", 0, 1, lambda c: SUNK_HEIGHT, lambda c: c.arena_height, "m",
        "height of the centre at its last flight apex (the start height before the first)",
    ),
)  # fmt: skip

PADDLE_FIELDS = (
    Field(
        "paddle_height", 0, 1, lambda c: 0.0, lambda c: c.arena_height + _node_reach(c), "m",
        "the paddle's height",
    ),
    Field(
        "paddle_in_reach", 0, 1, lambda c: 0.0, lambda c: 1.0, "-",
        "1 if the paddle can strike at the next step, else 0 (a falling ball in flight, once per flight)",
    ),
    Field(
        "paddle_impulse", 0, 1, lambda c: 0.0, lambda c: c.paddle_max_impulse, "N s",
        "impulse delivered at the last step",
    ),
)  # fmt: skip


def _starts(table: tuple[Field, ...]) -> dict[str, tuple[int, int]]:
    """Name -> start of each field of ``table`` as (entries per node, fixed entries) before it."""
    per_node = fixed = 0
    out = {}
    for field in table:
        out[field.name] = (per_node, fixed)
        per_node += field.per_node
        fixed += field.fixed
    return out


_START = _starts(FIELDS + PADDLE_FIELDS)  # paddle mode appends: the other fields start alike in both
OBS_NODE_POSITION = _START["node_position"]
OBS_NODE_VELOCITY = _START["node_velocity"]
OBS_CENTRE_OF_MASS_POSITION = _START["centre_of_mass_position"]
OBS_CENTRE_OF_MASS_VELOCITY = _START["centre_of_mass_velocity"]
OBS_GROUND_NORMAL_FORCE = _START["ground_normal_force"]
OBS_PRESSURE = _START["pressure"]
OBS_PRESSURE_SETPOINT = _START["pressure_setpoint"]
OBS_TARGET_HEIGHT = _START["target_height"]
OBS_LAST_APEX = _START["last_apex"]
OBS_PADDLE_HEIGHT = _START["paddle_height"]
OBS_PADDLE_IN_REACH = _START["paddle_in_reach"]
OBS_PADDLE_IMPULSE = _START["paddle_impulse"]


@kernel
def field_start(field, n_nodes):
    """Index of the first entry of ``field`` (an ``OBS_*`` constant) for a ring of ``n_nodes`` nodes."""
    return field[0] * n_nodes + field[1]


def fields(paddle: bool) -> tuple[Field, ...]:
    """The fields of the observation in order: :data:`FIELDS`, then :data:`PADDLE_FIELDS` if ``paddle``."""
    return FIELDS + PADDLE_FIELDS if paddle else FIELDS


def size(n_nodes: int, paddle: bool) -> int:
    """Length of the observation vector for a ring of ``n_nodes`` nodes."""
    return sum(field.size(n_nodes) for field in fields(paddle))


def structure(n_nodes: int, paddle: bool) -> dict[str, slice]:
    """Name -> slice of the observation vector for a ring of ``n_nodes`` nodes."""
    out = {}
    for field in fields(paddle):
        first = field_start(_START[field.name], n_nodes)
        out[field.name] = slice(first, first + field.size(n_nodes))
    return out


def bounds(config: Settings, paddle: bool) -> tuple[NDArray[np.float32], NDArray[np.float32]]:
    """(low, high) float32 bounds of the observation vector of the env configured by ``config``."""
    n = config.n_nodes
    parts = structure(n, paddle)
    low = np.full(size(n, paddle), np.nan)  # a slot no field covers stays NaN
    high = np.full(size(n, paddle), np.nan)
    for field in fields(paddle):
        low[parts[field.name]] = field.low(config)
        high[parts[field.name]] = field.high(config)
    return low.astype(np.float32), high.astype(np.float32)
