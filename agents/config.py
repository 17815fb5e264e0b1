"""What every agent module shares: the env ids, the success tolerance, the algorithms, and the
hyperparameter files (RL Baselines3 Zoo's format: one YAML entry per env id, i.e. per action mode).

The action modes (:data:`MODE_ENV_IDS`) are the ring's "pressure" and "paddle" (InflatedBall-v3's
ids) and the 3-D ball's "pressure3d" and "paddle3d" (InflatedBall3D-v0's ids; the env itself is
given "pressure" or "paddle": :func:`env_action_mode`).

* ``agents/hyperparams/{algo}.yml``: an algorithm's hyperparameters and its task's env keywords
  (:func:`load_hyperparams`, :func:`task_env_kwargs`);
* ``agents/hyperparams/heuristic.yml``: the scripted controllers' tuned parameters
  (:func:`tuned_heuristic`, and the 3-D ball's :func:`tuned_heuristic3d`, written by ``agents.tune``).
"""

from __future__ import annotations

import json
import pathlib
from collections.abc import Mapping
from typing import Any

import yaml

from ballenv.envs import BALL3D_ENV_IDS, ENV_IDS

ENV_ID = "ballenv:InflatedBall-v3"
SUCCESS_TOLERANCE = 0.05  # relative apex error counted as a success
ALGORITHMS = ("ppo", "sac")
HYPERPARAMS = pathlib.Path(__file__).parent / "hyperparams"
HEURISTIC_PARAMS = pathlib.Path(__file__).parent / "hyperparams" / "heuristic.yml"


class UsageError(ValueError):
    """A command-line or hyperparameter mistake: reported in one line, before any run folder exists."""


# action mode -> its env id: the ring's modes, and the 3-D ball's as "pressure3d", "paddle3d"
MODE_ENV_IDS = {**ENV_IDS, **{f"{mode}3d": name for mode, name in BALL3D_ENV_IDS.items()}}
MODES = tuple(MODE_ENV_IDS)


def env_id(mode: str) -> str:
    """The registered id of action mode ``mode`` (:data:`MODE_ENV_IDS`), module-qualified so that
    spawned workers import ballenv."""
    return f"ballenv:{MODE_ENV_IDS[mode]}"


def env_action_mode(mode: str) -> str:
    """The env's own ``action_mode`` keyword of action mode ``mode`` ("paddle3d" -> "paddle")."""
    return mode.removesuffix("3d")


def is_ball3d(mode: str) -> bool:
    """Whether action mode ``mode`` is one of the 3-D ball's (InflatedBall3D-v0's ids)."""
    return MODE_ENV_IDS[mode] in BALL3D_ENV_IDS.values()


def mode_of(registered: str) -> str | None:
    """The action mode of env id ``registered`` (with or without the ``ballenv:`` prefix; None for
    an id of no mode here)."""
    name = registered.removeprefix("ballenv:")
    return next((mode for mode, other in MODE_ENV_IDS.items() if other == name), None)


def load_hyperparams(algo: str, mode: str, conf_file: str | None = None) -> dict[str, Any]:
    """The YAML entry for the env id of action mode ``mode`` (a dict) in ``conf_file`` (a path, or
    the name of a file in ``agents/hyperparams`` without ``.yml``; default: ``algo``'s file); a
    :class:`UsageError` if there is no such file or entry."""
    path = HYPERPARAMS / f"{algo}.yml"
    if conf_file is not None:
        given = pathlib.Path(conf_file)
        path = given if given.suffix in (".yml", ".yaml") else HYPERPARAMS / f"{conf_file}.yml"
        if not path.exists():
            names = sorted(f.stem for f in HYPERPARAMS.glob("*.yml"))
            raise UsageError(f"--conf-file = {conf_file!r}: no such file (the project's: {names})")
    table = yaml.safe_load(path.read_text()) or {}
    name = MODE_ENV_IDS[mode]
    if name not in table:
        raise UsageError(f"{path} has no entry for {name} (--action-mode {mode}): {sorted(table)}")
    return dict(table[name])


def task_env_kwargs(
    algo: str, mode: str, extra: dict[str, Any] | None = None, entry: Mapping[str, Any] | None = None
) -> dict[str, Any]:
    """The env keywords of the task ``algo`` trains on in action mode ``mode``: the ``env_kwargs``
    of ``entry`` (default: the YAML entry), updated with ``extra`` (a command line's
    ``--env-kwargs``), and the env's action mode (:func:`env_action_mode`). What the training envs
    get, and what every policy compared with the trained one is scored on."""
    entry = load_hyperparams(algo, mode) if entry is None else entry
    return {**(entry.get("env_kwargs") or {}), **(extra or {}), "action_mode": env_action_mode(mode)}


def parse_env_kwargs(text: str) -> dict[str, Any]:
    """``--env-kwargs`` as a JSON object (e.g. '{"action_mode": "paddle"}')."""
    try:
        value = json.loads(text)
    except json.JSONDecodeError as exc:
        raise SystemExit(f"--env-kwargs = {text!r} is not a JSON object: {exc}") from exc
    if not isinstance(value, dict):
        raise SystemExit(f"--env-kwargs = {text!r} must be a JSON object of env keyword arguments")
    return value


def heuristic_table() -> dict[str, dict[str, float]]:
    """The tuned controllers' parameters of ``hyperparams/heuristic.yml``: env id -> dict."""
    return (yaml.safe_load(HEURISTIC_PARAMS.read_text()) if HEURISTIC_PARAMS.exists() else None) or {}


def tuned_heuristic(mode: str) -> dict[str, float]:
    """The scripted controller's tuned parameters for action mode ``mode`` (a dict; empty if none)."""
    return dict(heuristic_table().get(ENV_IDS[mode]) or {})


def tuned_heuristic3d(mode: str) -> dict[str, float]:
    """The 3-D ball's scripted controller's tuned parameters for action mode ``mode`` (a dict; empty
    if none), under its env id (``ballenv.envs.BALL3D_ENV_IDS``)."""
    return dict(heuristic_table().get(BALL3D_ENV_IDS[mode]) or {})
