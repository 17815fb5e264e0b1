"""Observation wrappers an agent may train behind, named in the hyperparameter files by RL Baselines3
Zoo's ``env_wrapper`` key (``agents.wrappers.BallStateObservation``); ``agents.train`` applies it to
the training and evaluation envs and ``agents.evaluate`` to a saved model's env."""

from __future__ import annotations

import importlib
from typing import Any

import gymnasium as gym
import numpy as np
from numpy.typing import NDArray

from ballenv.envs.inflated_ball import ball_env
from ballenv.envs.observation import MAX_NODE_FORCE

KEPT_FIELDS = (
    "centre_of_mass_position", "centre_of_mass_velocity", "pressure", "pressure_setpoint",
    "target_height", "last_apex", "paddle_height", "paddle_in_reach", "paddle_impulse",
)  # fmt: skip


class BallStateObservation(
    gym.ObservationWrapper[NDArray[np.float32], NDArray[np.float32], NDArray[np.float32]]
):
    """The ball as a body: the fields of :data:`KEPT_FIELDS` the env has (centre of mass, gas,
    target, last apex, paddle), then the total ground normal force (N) in place of the per-node
    shape. 9 entries in pressure mode, 12 in paddle mode (the env's 5 N + 8 and 5 N + 11). What
    the scripted controllers read; the node states, whose small flight vibrations the running
    normalisation would blow up, are left out."""

    def __init__(self, env: gym.Env[NDArray[np.float32], NDArray[np.float32]]) -> None:
        super().__init__(env)
        structure = ball_env(env).observation_structure
        self.parts = [structure[name] for name in KEPT_FIELDS if name in structure]
        self.force = structure["ground_normal_force"]
        n_nodes = self.force.stop - self.force.start
        space = env.observation_space
        assert isinstance(space, gym.spaces.Box), space  # the env's Box, bounds per entry
        low = np.concatenate([space.low[p] for p in self.parts] + [[0.0]])
        high = np.concatenate([space.high[p] for p in self.parts] + [[n_nodes * MAX_NODE_FORCE]])
        self.observation_space = gym.spaces.Box(low.astype(np.float32), high.astype(np.float32))

    def observation(self, observation: NDArray[np.float32]) -> NDArray[np.float32]:
        kept = [observation[p] for p in self.parts]
        return np.concatenate(kept + [[observation[self.force].sum()]]).astype(np.float32)


def wrapper_class(name: str | None) -> type[gym.ObservationWrapper[Any, Any, Any]] | None:
    """The wrapper class named ``"module.Class"`` (RL Zoo's ``env_wrapper``), or None for None."""
    if not name:
        return None
    module, _, cls = str(name).rpartition(".")
    try:
        return getattr(importlib.import_module(module), cls)
    except (ImportError, AttributeError, ValueError) as exc:
        raise ValueError(f"env_wrapper = {name!r} is not an importable 'module.Class' ({exc})") from None
