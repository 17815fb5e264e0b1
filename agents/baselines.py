"""Every policy InflatedBall-v3 is scored with, made by name (:func:`make_policy`); each is an
``agents.policies.Policy``: ``reset(seed)`` at an episode start, then ``act(obs) -> action``.

* ``"random"``, ``"heuristic"``: :class:`agents.policies.RandomPolicy`,
  :class:`agents.policies.HeuristicPolicy` (the scripted controller of the env's action mode);
* :class:`agents.lookahead.LookaheadPump` / :class:`agents.lookahead.LookaheadPaddle` ("lookahead"):
  the privileged references, the pump's amplitude or the paddle's strike of each bounce found by
  trying candidates on copies of the simulator;
* :class:`ModelPolicy`: a saved Stable-Baselines3 model (deterministic actions), with the
  observation normalisation (``VecNormalize`` statistics) it was trained with.
"""

from __future__ import annotations

import os
import pathlib
from collections.abc import Callable
from typing import Any

import gymnasium as gym
import numpy as np
from numpy.typing import NDArray

from .config import ALGORITHMS
from .lookahead import lookahead_for
from .normalization import Normalization
from .normalization import load as load_normalization
from .policies import HeuristicPolicy, Policy, RandomPolicy
from .signatures import require_signed
from .wrappers import wrapper_class

NAMED_POLICIES = ("random", "heuristic", "lookahead")  # make_policy's policies by name


class ModelPolicy:
    """A saved Stable-Baselines3 model (``model.zip`` of a run folder, or any path to a .zip).

    The model is loaded only if this user's training signed it, or with ``trust``
    (:func:`agents.signatures.require_signed`: a saved model is a pickle, which runs code). The
    observation wrapper the run was trained behind (``env_wrapper`` in its ``config.yml``) and the
    observation normalisation (``vecnormalize.npz`` next to it, ``best_vecnormalize.npz`` for
    ``best_model.zip``; :mod:`agents.normalization`) are applied, the latter frozen, if present; a
    wrapper that also acts (``action`` and ``restart`` methods: ``agents.wrappers.ResidualPump``)
    turns the model's action into the env's and is restarted at each episode start; one that plays
    the env itself (an ``act`` method: ``agents.wrappers.PumpAmplitude``) is given each env
    observation and asks the model when it needs an action.
    """

    name = "trained"

    def __init__(
        self,
        env: gym.Env[Any, Any],
        path: str | os.PathLike[str],
        algo: str | None = None,
        trust: bool = False,
    ) -> None:
        from stable_baselines3 import PPO, SAC

        path = pathlib.Path(path)
        if path.is_dir():
            path = path / ("best_model.zip" if (path / "best_model.zip").exists() else "model.zip")
        if not path.exists():
            raise ValueError(f"agents.evaluate: policy file {str(path)!r} does not exist")
        require_signed(path, trust)  # a saved model is a pickle: only this user's runs, or --trust
        algo = algo or _algo_of(path)
        self.wrapper = _run_wrapper(path, env)
        self.shape = env.action_space.shape or (1,)  # the env's action: (1,), or (3,) for the 3-D paddle
        classes: dict[str, type[PPO] | type[SAC]] = {"ppo": PPO, "sac": SAC}
        self.model = classes[algo].load(path, device="cpu")
        self.normalize = _normalization(path, trust)

    def reset(self, seed: int) -> None:
        restart = getattr(self.wrapper, "restart", None)
        if restart is not None:
            restart()

    def act(self, obs: NDArray[np.float32]) -> NDArray[np.float32]:
        plays = getattr(self.wrapper, "act", None)  # a wrapper that plays the env step by step
        if plays is not None:
            return np.asarray(plays(obs, self.decide), dtype=np.float32).reshape(self.shape)
        if self.wrapper is not None:
            obs = self.wrapper.observation(obs)
        action = self.decide(obs)
        to_env = getattr(self.wrapper, "action", None)  # a wrapper that also acts (ResidualPump)
        return action if to_env is None else np.asarray(to_env(action), dtype=np.float32).reshape(self.shape)

    def decide(self, obs: NDArray[np.float32]) -> NDArray[np.float32]:
        """The model's deterministic action for a wrapped observation (normalised here, if the run
        normalised its observations)."""
        if self.normalize is not None:
            obs = self.normalize.apply(obs)
        action, _ = self.model.predict(obs, deterministic=True)
        return np.asarray(action, dtype=np.float32).reshape(self.shape)


def _normalization(path: pathlib.Path, trust: bool) -> Normalization | None:
    """The run's observation statistics for the model at ``path`` (plain data), or, from a run folder
    of an older ballenv, its pickled ``VecNormalize`` (only with ``trust``); None if there are none."""
    stem = "best_vecnormalize" if path.name == "best_model.zip" else "vecnormalize"
    plain, pickled = path.parent / f"{stem}.npz", path.parent / f"{stem}.pkl"
    if plain.exists():
        return load_normalization(plain)
    if not pickled.exists():
        return None
    require_signed(pickled, trust)
    import pickle

    with open(pickled, "rb") as f:
        normalize = pickle.load(f)  # noqa: S301 - trusted by the user (--trust)
    if not normalize.norm_obs:
        return None
    rms = normalize.obs_rms
    return Normalization(np.asarray(rms.mean), np.asarray(rms.var), normalize.clip_obs, normalize.epsilon)


def _run_wrapper(path: pathlib.Path, env: gym.Env[Any, Any]) -> gym.ObservationWrapper[Any, Any, Any] | None:
    """The observation wrapper of the run folder holding ``path`` around ``env`` (else None)."""
    config = path.parent / "config.yml"
    if not config.exists():
        return None
    import yaml

    cls = wrapper_class(yaml.safe_load(config.read_text()).get("env_wrapper"))
    return None if cls is None else cls(env)


def _algo_of(path: pathlib.Path) -> str:
    """The algorithm of a saved model from its run folder's config (or its file name)."""
    config = path.parent / "config.yml"
    if config.exists():
        import yaml

        algo = yaml.safe_load(config.read_text()).get("algo")
        if algo in ALGORITHMS:
            return algo
    for algo in ALGORITHMS:
        if algo in path.as_posix().lower():
            return algo
    raise ValueError(
        f"agents.evaluate: cannot tell the algorithm of {str(path)!r}: pass --algo (one of {ALGORITHMS})"
    )


def make_policy(
    spec: str | os.PathLike[str] | Callable[[gym.Env[Any, Any]], Policy],
    env: gym.Env[Any, Any],
    algo: str | None = None,
    trust: bool = False,
) -> Policy:
    """``"random"``, ``"heuristic"``, ``"lookahead"`` (the action mode's privileged reference,
    :mod:`agents.lookahead`), a path to a saved model / run folder (loaded only if this user's
    training signed it, or with ``trust``), or a callable ``env -> policy`` -> a policy."""
    if callable(spec):
        return spec(env)
    if spec == "random":
        return RandomPolicy(env)
    if spec == "heuristic":
        return HeuristicPolicy(env)
    if spec == "lookahead":
        return lookahead_for(env)
    path = pathlib.Path(spec)
    if not path.exists():
        raise ValueError(
            f"agents.evaluate: policy = {str(spec)!r} is invalid: must be one of {NAMED_POLICIES}, a "
            "saved model (.zip) or a train.py run folder (no such file or folder)"
        )
    return ModelPolicy(env, path, algo, trust)
