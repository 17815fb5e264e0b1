"""``BodyObservation``: the 3-D ball seen as a body, for agents: a short observation of the ball's
centre, velocity and spin, its gas and the targets, in place of the vertex states.

The spin is the ball's angular velocity about its centre of mass (rad/s), ``w = I^-1 L`` from the
observed vertex positions ``r_i`` and velocities ``u_i`` relative to the centre, with the vertices'
lumped masses ``m_i``: ``L = sum_i m_i r_i x u_i``, ``I = sum_i m_i (|r_i|^2 1 - r_i r_i^T)``.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from numpy.typing import NDArray

from ...shell.skin.model import build_model
from . import observation
from .env import ball3d_env
from .observation import MAX_NODE_FORCE

MAX_SPIN = 1e3  # rad/s, bound of the spin observation
VERTEX_FIELDS = ("vertex_position", "vertex_velocity", "ground_normal_force")


class BodyObservation(gym.ObservationWrapper[NDArray[np.float32], NDArray[np.float32], NDArray[np.float32]]):
    """An InflatedBall3D env observed as a body: its observation's fields without
    ``vertex_position``, ``vertex_velocity`` and ``ground_normal_force``, in their order, then
    ``spin`` (3, rad/s) and ``ground_force`` (1, N: the sum of the vertices' normal ground reactions);
    ``observation_structure`` maps these names to slices."""

    def __init__(self, env: gym.Env[NDArray[np.float32], NDArray[np.float32]]) -> None:
        super().__init__(env)
        inner = ball3d_env(env)
        self.inner_structure = inner.observation_structure
        self.mass = _lumped_masses(inner)  # (V,) kg
        kept = [(name, s) for name, s in self.inner_structure.items() if name not in VERTEX_FIELDS]
        low, high = observation.bounds(inner.config)
        lows = [low[s] for _, s in kept] + [np.full(3, -MAX_SPIN), np.zeros(1)]
        highs = [high[s] for _, s in kept] + [
            np.full(3, MAX_SPIN),
            np.full(1, MAX_NODE_FORCE * len(self.mass)),
        ]
        self.kept = [s for _, s in kept]
        self.observation_structure: dict[str, slice] = {}
        start = 0
        for name, size in [(n, s.stop - s.start) for n, s in kept] + [("spin", 3), ("ground_force", 1)]:
            self.observation_structure[name] = slice(start, start + size)
            start += size
        self.observation_space = self.box = spaces.Box(
            np.concatenate(lows).astype(np.float32),
            np.concatenate(highs).astype(np.float32),
            dtype=np.float32,
        )

    def observation(self, observation: NDArray[np.float32]) -> NDArray[np.float32]:
        s = self.inner_structure
        r = observation[s["vertex_position"]].reshape(-1, 3).astype(np.float64)
        u = observation[s["vertex_velocity"]].reshape(-1, 3).astype(np.float64)
        spin = np.clip(angular_velocity(self.mass, r, u), -MAX_SPIN, MAX_SPIN)
        force = float(observation[s["ground_normal_force"]].astype(np.float64).sum())
        parts = [observation[k] for k in self.kept] + [
            spin.astype(np.float32),
            np.array([force], dtype=np.float32),
        ]
        out = np.concatenate(parts).astype(np.float32)
        return np.clip(out, self.box.low, self.box.high)


def angular_velocity(
    mass: NDArray[np.float64], r: NDArray[np.float64], u: NDArray[np.float64]
) -> NDArray[np.float64]:
    """``I^-1 L`` (rad/s) of masses ``mass`` (kg) at ``r`` (m) moving at ``u`` (m/s) about their
    centre (module doc)."""
    momentum = (mass[:, None] * np.cross(r, u)).sum(axis=0)
    inertia = np.eye(3) * float(mass @ np.sum(r * r, axis=1)) - (mass[:, None] * r).T @ r
    return np.linalg.solve(inertia, momentum)


def _lumped_masses(env: Any) -> NDArray[np.float64]:
    """The vertices' lumped masses (kg) of the env's ball."""
    scene = env.ball.scene
    return build_model(scene.shells[0], scene.gas_exponent, scene.atmospheric_pressure).mass
