"""Train a Stable-Baselines3 agent on InflatedBall-v3, then score it next to the baselines.

    python train.py --algo ppo --action-mode pressure            # the README's main command
    python train.py --algo sac --action-mode paddle --total-timesteps 50000 --seed 3
    ballenv-train --algo ppo --env-kwargs '{"fidelity": "balanced"}' --n-envs 2   # when installed
    python train.py --algo ppo --action-mode paddle --conf-file ppo_cloned \
        --demonstrations runs/demonstrations_paddle.npz                   # cloned, then PPO
    python train.py --action-mode pressure --warm-start clone --demo-episodes 60 \
        --total-timesteps 2048 --final-episodes 30 --vec-env subproc     # make train: all in one
    python train.py --algo ppo --action-mode paddle3d --total-timesteps 50000 --final-episodes 0
                                                  # the 3-D ball: InflatedBall3DPaddle-v0

Hyperparameters come from ``agents/hyperparams/{algo}.yml``, or ``--conf-file`` (one entry per env
id, i.e. per action mode; the command line overrides the budget, the number of envs and the env
keyword arguments).
The 3-D ball's modes ("pressure3d", "paddle3d": InflatedBall3D-v0 and InflatedBall3DPaddle-v0)
train the same way; their runs are scored by ``python -m agents.evaluate3d RUN`` (with
``--final-episodes`` above 0, train says so and writes no scoreboard: the scoreboard's baselines
are the ring's).
``--demonstrations`` pretrains a PPO policy on the privileged lookahead's demonstrations of a
bounce-level task (``agents.imitation``) and evaluates it before the first update, so the best
model may be the clone itself. ``--warm-start clone`` does it all in one command: it records the
lookahead's demonstrations of ``--demo-episodes`` episodes (training seeds from ``DEMO_SEED``, one
process per core with ``--vec-env subproc``; kept as ``demonstrations.npz``), clones them and runs
PPO with ``--conf-file`` (default ``ppo_cloned``). A run writes one folder
``{log_dir}/{algo}_{mode}_seed{seed}[_k]`` holding:

* ``config.yml`` (algorithm, hyperparameters, env keyword arguments, seed, versions) and
  ``command.txt`` (the exact command);
* ``model.zip`` and ``vecnormalize.npz`` (final), ``best_model.zip`` and ``best_vecnormalize.npz``
  (best periodic evaluation), ``signatures.json`` (their HMACs under this user's key, so that
  evaluation loads them without ``--trust``: ``agents.signatures``), ``checkpoints/``,
  ``evaluations.npz``, Monitor logs and TensorBoard logs (``tensorboard --logdir runs``);
* ``scores.md`` / ``scores.json``: the scoreboard: the best model, the heuristic and random actions
  scored by ``agents.evaluate`` on the same held-out seeds (10,000 on: never trained or cloned on),
  with reference rows read from results files (:mod:`agents.scoreboard`), whether the agent beats
  the heuristic (95 % intervals apart) and each phase's wall time; ``learning_curve.png`` (if a
  periodic evaluation ran) and ``clip.gif``, the trained agent's first 4 s of the first held-out
  episode (if Pillow is installed). The output names what was written, and what was not and why.
* TensorBoard's ``task/apex_error``, ``task/success_rate`` and ``task/apexes``: the training
  episodes' apexes per rollout (:func:`task_metrics`).
"""

from __future__ import annotations

import argparse
import contextlib
import difflib
import inspect
import json
import os
import pathlib
import shlex
import shutil
import sys
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import yaml

if TYPE_CHECKING:
    from stable_baselines3.common.base_class import BaseAlgorithm
    from stable_baselines3.common.callbacks import BaseCallback
    from stable_baselines3.common.vec_env import VecEnv


from ballenv.files import write_text

from . import checkpoints
from .config import (
    MODES,
    SUCCESS_TOLERANCE,
    UsageError,
    env_id,
    is_ball3d,
    load_hyperparams,
    mode_of,
    parse_env_kwargs,
    task_env_kwargs,
)
from .evaluate import DEFAULT_SEED, Score, evaluate
from .imitation import TASKS, WRAPPERS, Demonstrations, pretrain, record_in_parallel
from .normalization import save as save_normalization
from .scoreboard import board, references, verdict
from .signatures import sign
from .wrappers import wrapper_class

ROOT = pathlib.Path(__file__).resolve().parent.parent  # holds agents/: on a Ray worker's PYTHONPATH
RUN_KEYS = ("n_timesteps", "n_envs", "policy", "normalize", "env_kwargs", "env_wrapper")
OnEvaluation = Callable[[int, float], bool]  # (env steps, mean return) -> go on training
DEMO_SEED = 5_000  # --warm-start clone's demonstrations: training seeds from here (held-out: 10,000 on)


def parse_args(argv: Sequence[str] | None = None) -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--algo", choices=("ppo", "sac"), default="ppo", help="algorithm (default ppo)")
    p.add_argument(
        "--action-mode",
        choices=MODES,
        default="pressure",
        help="env action mode (pressure3d, paddle3d: the 3-D ball)",
    )
    p.add_argument("--env-kwargs", type=parse_env_kwargs, default=None, help="JSON object of env keywords")
    p.add_argument(
        "--conf-file", default=None, metavar="FILE",
        help="hyperparameters in RL Zoo's YAML format instead of agents/hyperparams/{algo}.yml: a path, or "
        "the name of a file there (e.g. ppo_cloned)",
    )  # fmt: skip
    p.add_argument(
        "--hyperparams", type=parse_env_kwargs, default=None, help="JSON object overriding the YAML"
    )
    p.add_argument("--n-envs", type=int, default=None, help="parallel envs (default: from the YAML)")
    p.add_argument(
        "--vec-env", choices=("subproc", "dummy"), default="dummy",
        help="subproc: one process per env (uses the cores); dummy: all in this process",
    )  # fmt: skip
    p.add_argument("--seed", type=int, default=0, help="seed of the run (envs get seed, seed + 1, ...)")
    p.add_argument("--total-timesteps", type=int, default=None, help="env steps (default: from the YAML)")
    p.add_argument("--eval-freq", type=int, default=40_000, help="env steps between evaluations")
    p.add_argument("--eval-episodes", type=int, default=5, help="episodes per periodic evaluation")
    p.add_argument(
        "--final-episodes", type=int, default=10, help="held-out episodes of the final scores (0: none)"
    )
    p.add_argument("--log-dir", default="runs", help="parent folder of the run folder")
    p.add_argument(
        "--demonstrations", default=None, metavar="FILE",
        help="pretrain the policy on these lookahead demonstrations (python -m agents.imitation) "
        "before learning; PPO behind the bounce-level task they were recorded in",
    )  # fmt: skip
    p.add_argument(
        "--warm-start", choices=("none", "clone"), default="none",
        help="clone: record the lookahead's demonstrations (--demo-episodes, on training seeds; or "
        "read --demonstrations), clone them into the policy, then PPO with --conf-file (default "
        "ppo_cloned); what make train runs",
    )  # fmt: skip
    p.add_argument(
        "--demo-episodes", type=int, default=40,
        help="episodes the lookahead demonstrates for --warm-start clone (about 6 s each on one core, "
        "recorded in one process per env up to the cores)",
    )  # fmt: skip
    p.add_argument("--no-baselines", action="store_true", help="score only the trained agent at the end")
    p.add_argument(
        "--checkpoint-minutes", type=float, default=10.0,
        help="save the resumable state (RUN/resume) every this many minutes (default 10; 0: only on Ctrl-C)",
    )  # fmt: skip
    p.add_argument(
        "--resume", default=None, metavar="RUN",
        help="go on with the run folder RUN from its resumable state, with its own settings",
    )  # fmt: skip
    return p.parse_args(argv)


def add_cluster_argument(p: argparse.ArgumentParser, runs: str) -> None:
    """The ``--ray`` option of a command whose ``runs`` (e.g. "the training seeds") can be Ray
    tasks (``ballenv.cluster.run_tasks``)."""
    p.add_argument(
        "--ray", dest="cluster", metavar="ADDRESS", type=check_cluster_name, default=None,
        help=f"run {runs} as Ray tasks: 'local' (a Ray cluster on this machine, one task per core), "
        "'auto' (the running cluster) or its address (host:6379, ray://host:10001); default: one "
        "after the other in this process",
    )  # fmt: skip


def check_cluster_name(text: str) -> str:
    """``--ray``'s value, checked by ``ballenv.cluster.check_cluster`` (argparse reports its error)."""
    from ballenv.cluster import check_cluster

    try:
        return str(check_cluster(text))
    except ValueError as err:
        raise argparse.ArgumentTypeError(str(err)) from None


def run_folder(log_dir: str | os.PathLike[str], algo: str, mode: str, seed: int) -> pathlib.Path:
    base = pathlib.Path(log_dir) / f"{algo}_{mode}_seed{seed}"
    path, k = base, 1
    while path.exists():
        k += 1
        path = base.with_name(f"{base.name}_{k}")
    path.mkdir(parents=True)
    return path


@contextlib.contextmanager
def removed_on_failure(run: pathlib.Path, made_log_dir: bool, keep: bool = False) -> Iterator[pathlib.Path]:
    """Remove the run folder ``run`` if the block raises (and its parent, the log folder, if
    ``made_log_dir`` and it is left empty): a setup that fails leaves no half-made run behind. A run
    being resumed (``keep``) is never removed."""
    try:
        yield run
    except BaseException:
        if keep:
            raise
        shutil.rmtree(run, ignore_errors=True)
        if made_log_dir:
            with contextlib.suppress(OSError):  # not empty: another run is there
                run.parent.rmdir()
        raise


def make_envs(
    env_kwargs: dict[str, Any],
    n_envs: int,
    seed: int,
    normalize: bool,
    gamma: float,
    monitor_dir: pathlib.Path | None = None,
    training: bool = True,
    subproc: bool = False,
    wrapper: str | None = None,
    mode: str | None = None,
) -> VecEnv:
    """The vector env of the id of action mode ``mode`` (default: ``env_kwargs["action_mode"]``)."""
    from stable_baselines3.common.env_util import make_vec_env
    from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv, VecNormalize

    mode = mode or env_kwargs["action_mode"]
    compile_once(env_kwargs, mode)
    envs = make_vec_env(
        env_id(mode), n_envs=n_envs, seed=seed, env_kwargs=env_kwargs,
        wrapper_class=wrapper_class(wrapper),
        vec_env_cls=SubprocVecEnv if subproc and n_envs > 1 else DummyVecEnv,
        monitor_dir=None if monitor_dir is None else str(monitor_dir),
    )  # fmt: skip
    if normalize:
        envs = VecNormalize(envs, norm_obs=True, norm_reward=training, gamma=gamma, training=training)
    return envs


def compile_once(env_kwargs: dict[str, Any], mode: str | None = None) -> None:
    """Reset and step one env (of action mode ``mode``, default ``env_kwargs["action_mode"]``) here,
    before any worker process starts: numba compiles the simulator once (or loads it from its cache)
    and the workers load it from the cache instead of each compiling it. Also the warm-up of a
    cluster's nodes (``ballenv.cluster.run_tasks``'s ``warm``)."""
    import gymnasium as gym

    env = gym.make(env_id(mode or env_kwargs["action_mode"]), **env_kwargs)
    env.reset(seed=0)
    env.step(env.action_space.sample())
    env.close()


def callbacks(
    run: pathlib.Path,
    eval_env: VecEnv,
    args: argparse.Namespace,
    n_envs: int,
    total: int,
    on_evaluation: OnEvaluation | None = None,
    evaluate_at_start: bool = False,
) -> list[BaseCallback]:
    """The periodic evaluation (keeping the best model; with ``evaluate_at_start``, of the policy
    the training starts from too: a pretrained one), checkpoints and a progress bar."""
    from stable_baselines3.common.callbacks import BaseCallback, CheckpointCallback, EvalCallback

    class Evaluation(EvalCallback):
        """Stable-Baselines3's periodic evaluation, also before the first update if ``at_start``;
        a resumed run goes on from the evaluations and the best model it had."""

        at_start = evaluate_at_start

        def _on_training_start(self) -> None:
            super()._on_training_start()
            earlier = run / "evaluations.npz"
            if args.resume and earlier.exists():
                with np.load(earlier) as old:
                    self.evaluations_timesteps = [int(s) for s in old["timesteps"]]
                    self.evaluations_results = [list(r) for r in old["results"]]
                    self.evaluations_length = [list(n) for n in old["ep_lengths"]]
                means = [float(np.mean(r)) for r in self.evaluations_results]
                self.best_mean_reward = max(means, default=-np.inf)
            if self.at_start:  # n_calls is 0, a multiple of eval_freq: _on_step evaluates
                self._on_step()

    class SaveNormalization(BaseCallback):
        """Save the VecNormalize statistics with each new best model, and sign both."""

        def _on_step(self) -> bool:
            env = self.model.get_vec_normalize_env()
            written = [run / "best_model.zip"]
            if env is not None:
                written.append(save_normalization(env, run / "best_vecnormalize.npz"))
            sign(written)
            return True

    class ProgressBar(BaseCallback):
        """A tqdm bar over env steps (SB3's own needs the `rich` package)."""

        def _on_training_start(self) -> None:
            from tqdm.auto import tqdm

            self.bar = tqdm(total=total, unit="step", desc=f"train {args.algo}", smoothing=0.1)

        def _on_step(self) -> bool:
            self.bar.n = self.num_timesteps
            self.bar.refresh() if self.n_calls % 50 == 0 else None
            return True

        def _on_training_end(self) -> None:
            self.bar.n = self.num_timesteps
            self.bar.close()

    class AfterEvaluation(BaseCallback):
        """Hand each periodic evaluation to ``report(env steps, mean return)``; its False stops the
        training (a pruned tuning trial)."""

        def __init__(self, report: OnEvaluation) -> None:
            super().__init__()
            self.report = report

        def _on_step(self) -> bool:
            assert isinstance(self.parent, EvalCallback)  # run after each of its evaluations
            return bool(self.report(self.num_timesteps, float(self.parent.last_mean_reward)))

    every = max(args.eval_freq // n_envs, 1)
    evaluation = Evaluation(
        eval_env, best_model_save_path=str(run), log_path=str(run), eval_freq=every,
        n_eval_episodes=args.eval_episodes, deterministic=True, callback_on_new_best=SaveNormalization(),
        callback_after_eval=None if on_evaluation is None else AfterEvaluation(on_evaluation), verbose=0,
    )  # fmt: skip
    checkpoints = CheckpointCallback(
        save_freq=max(total // (5 * n_envs), 1), save_path=str(run / "checkpoints"), name_prefix="model",
        save_vecnormalize=True,
    )  # fmt: skip
    return [evaluation, checkpoints, ProgressBar(), task_metrics()]


def task_metrics() -> BaseCallback:
    """A callback that logs the task's measures of the training episodes' flight apexes with each
    rollout (TensorBoard's ``task/apex_error``: the mean of ``|h - h_target| / h_target`` over the
    rollout's apexes; ``task/success_rate``: the share of them within ``SUCCESS_TOLERANCE``;
    ``task/apexes``: how many), read from the envs' ``info`` (``apex_count``, ``apex_height``,
    ``target_height``: a bounce-level task's step reports the apex that ended it). A rollout
    without an apex logs nothing."""
    from stable_baselines3.common.callbacks import BaseCallback

    class TaskMetrics(BaseCallback):
        def _on_rollout_start(self) -> None:
            self.errors: list[float] = []

        def _on_step(self) -> bool:
            for info in self.locals.get("infos", ()):
                if info.get("apex_count", 0) > 0:
                    target = float(info["target_height"])
                    self.errors.append(abs(float(info["apex_height"]) - target) / target)
            return True

        def _on_rollout_end(self) -> None:
            if not self.errors:
                return
            errors = np.asarray(self.errors)
            self.logger.record("task/apex_error", float(errors.mean()))
            self.logger.record("task/success_rate", float(np.mean(errors <= SUCCESS_TOLERANCE)))
            self.logger.record("task/apexes", int(errors.size))

    return TaskMetrics()


def check_hyperparams(cls: type[BaseAlgorithm], algo_kwargs: Mapping[str, Any]) -> None:
    """Raise :class:`UsageError` naming every key of ``algo_kwargs`` that the algorithm ``cls``
    does not take (with the nearest valid names)."""
    taken = inspect.signature(cls.__init__).parameters
    valid = sorted(p for p in taken if p not in ("self", "env", "policy"))
    unknown = sorted(set(algo_kwargs) - set(valid))
    if unknown:
        hints = []
        for key in unknown:
            near = difflib.get_close_matches(key, valid, 1)
            hints.append(f"{key!r} (did you mean {near[0]!r}?)" if near else repr(key))
        raise UsageError(
            f"unknown {cls.__name__} hyperparameter {', '.join(hints)}; valid: {', '.join(valid)} "
            f"(and the run keys {', '.join(RUN_KEYS)})"
        )


class LinearSchedule:
    """RL Baselines3 Zoo's ``lin_<value>``: ``value`` times the fraction of the training left
    (Stable-Baselines3's ``progress_remaining``, 1 at the start, 0 at the end)."""

    def __init__(self, value: float) -> None:
        self.value = value

    def __call__(self, progress_remaining: float) -> float:
        return progress_remaining * self.value


def schedules(algo_kwargs: Mapping[str, Any]) -> dict[str, Any]:
    """``algo_kwargs`` with RL Zoo's ``lin_<value>`` strings (``learning_rate``, ``clip_range``) as
    :class:`LinearSchedule`; a malformed one is a :class:`UsageError` naming it."""
    out = dict(algo_kwargs)
    for key in ("learning_rate", "clip_range"):
        value = out.get(key)
        if isinstance(value, str):
            head, _, number = value.partition("_")
            try:
                if head != "lin":
                    raise ValueError(head)
                out[key] = LinearSchedule(float(number))
            except ValueError:
                message = f"{key} = {value!r}: must be a number or 'lin_<number>' (e.g. lin_3e-4)"
                raise UsageError(message) from None
    return out


def check_demonstrated_task(args: argparse.Namespace, wrapper: str | None, option: str) -> None:
    """A :class:`UsageError` naming ``option`` unless the run is PPO behind a demonstrated task's
    wrapper (``agents.imitation.TASKS``) of its action mode."""
    if args.algo != "ppo" or wrapper not in WRAPPERS or TASKS[wrapper] != args.action_mode:
        raise UsageError(
            f"{option} needs --algo ppo and an env_wrapper of its --action-mode among {TASKS}; "
            f"got {args.algo}, {args.action_mode}, {wrapper}"
        )


def demonstration_seed(args: argparse.Namespace) -> int:
    """The seed of the first episode ``--warm-start clone`` demonstrates: ``DEMO_SEED`` plus the
    run's seed times ``--demo-episodes`` (runs of different seeds clone different episodes); all of
    them below the held-out episodes' seeds (``agents.evaluate.DEFAULT_SEED``), or a
    :class:`UsageError`."""
    if args.demo_episodes < 1:
        raise UsageError(f"--demo-episodes = {args.demo_episodes} is invalid: must be >= 1")
    first = DEMO_SEED + args.seed * args.demo_episodes
    if first < 0 or first + args.demo_episodes > DEFAULT_SEED:
        raise UsageError(
            f"--seed {args.seed} with --demo-episodes {args.demo_episodes}: the demonstrations' seeds "
            f"{first}..{first + args.demo_episodes - 1} must lie in [0, {DEFAULT_SEED}) (held-out from there)"
        )
    return first


def load_demonstrations(args: argparse.Namespace, wrapper: str | None) -> Demonstrations | None:
    """The demonstrations of ``args.demonstrations`` (None if not given); a :class:`UsageError` if
    the file does not load or the run is not PPO behind their task's wrapper."""
    if args.demonstrations is None:
        return None
    check_demonstrated_task(args, wrapper, "--demonstrations")
    try:
        demonstrations = Demonstrations.load(args.demonstrations)
    except (OSError, ValueError, KeyError) as err:
        raise UsageError(f"--demonstrations = {args.demonstrations!r}: {err}") from None
    if demonstrations.wrapper != wrapper:
        raise UsageError(
            f"--demonstrations = {args.demonstrations!r} are behind {demonstrations.wrapper}, the run "
            f"behind {wrapper} (python -m agents.imitation --wrapper {wrapper})"
        )
    return demonstrations


def main(argv: Sequence[str] | None = None) -> None:
    """``python train.py ...`` / ``ballenv-train ...``: train, save and score (see the module doc)."""
    try:
        train(parse_args(argv))
    except UsageError as err:
        sys.exit(f"ballenv-train: error: {err}")
    except KeyboardInterrupt:
        sys.exit(130)  # the resumable state is saved (train said where)


@dataclass(frozen=True)
class Plan:
    """A run's settings: its arguments and hyperparameters (the YAML's, or a resumed run's own) and
    what follows from them."""

    args: argparse.Namespace
    hp: dict[str, Any]
    env_kwargs: dict[str, Any]
    n_envs: int
    total: int  # env steps
    normalize: bool
    wrapper: str | None
    algo_kwargs: dict[str, Any]  # as written (config.yml)
    cls: Any  # the Stable-Baselines3 algorithm
    model_kwargs: dict[str, Any]  # with RL Zoo's schedules resolved
    gamma: float
    demonstrations: Demonstrations | None  # read from --demonstrations
    demo_seed: int | None  # --warm-start clone without a file: record episodes from this seed


def plan(args: argparse.Namespace) -> Plan:
    """The settings of ``args`` (a :class:`UsageError` for a mistaken one, before any folder exists)."""
    from stable_baselines3 import PPO, SAC

    if args.resume:
        args, hp = resumed(args)
    else:
        if args.warm_start == "clone" and args.algo != "ppo":
            check_demonstrated_task(args, None, "--warm-start clone")
        if args.warm_start == "clone" and args.conf_file is None:
            args = argparse.Namespace(**{**vars(args), "conf_file": "ppo_cloned"})
        hp = load_hyperparams(args.algo, args.action_mode, args.conf_file)
        hp.update(args.hyperparams or {})
    wrapper = hp.get("env_wrapper")
    demo_seed = None
    if args.warm_start == "clone":
        check_demonstrated_task(args, wrapper, "--warm-start clone")
        demo_seed = None if args.demonstrations else demonstration_seed(args)
    algo_kwargs = {k: v for k, v in hp.items() if k not in RUN_KEYS}
    classes: dict[str, type[PPO] | type[SAC]] = {"ppo": PPO, "sac": SAC}
    cls = classes[args.algo]
    check_hyperparams(cls, algo_kwargs)
    try:
        wrapper_class(wrapper)
    except ValueError as err:
        raise UsageError(str(err)) from None
    return Plan(
        args=args, hp=hp, env_kwargs=task_env_kwargs(args.algo, args.action_mode, args.env_kwargs, entry=hp),
        n_envs=args.n_envs or int(hp.get("n_envs", 1)), total=args.total_timesteps or int(hp["n_timesteps"]),
        normalize=bool(hp.get("normalize", True)), wrapper=wrapper, algo_kwargs=algo_kwargs, cls=cls,
        model_kwargs=schedules(algo_kwargs), gamma=float(algo_kwargs.get("gamma", 0.99)),
        demonstrations=load_demonstrations(args, wrapper), demo_seed=demo_seed,
    )  # fmt: skip


def run_config(p: Plan) -> dict[str, Any]:
    """What ``config.yml`` records of the run (what ``--resume`` reads back)."""
    import stable_baselines3
    import torch

    a = p.args
    return {
        "algo": a.algo, "env_id": env_id(a.action_mode), "env_kwargs": p.env_kwargs, "seed": a.seed,
        "total_timesteps": p.total, "n_envs": p.n_envs, "normalize": p.normalize,
        "policy": p.hp.get("policy", "MlpPolicy"), "env_wrapper": p.wrapper,
        "hyperparams": p.algo_kwargs, "eval_freq": a.eval_freq, "eval_episodes": a.eval_episodes,
        "vec_env": a.vec_env, "demonstrations": a.demonstrations, "warm_start": a.warm_start,
        "demo_episodes": a.demo_episodes if p.demo_seed is not None else None, "demo_seed": p.demo_seed,
        "versions": {"stable_baselines3": str(stable_baselines3.__version__),
                     "torch": str(torch.__version__)},
    }  # fmt: skip


def set_up(run: pathlib.Path, p: Plan, made_log_dir: bool) -> tuple[VecEnv, VecEnv, BaseAlgorithm]:
    """The run folder's records, the training and evaluation envs and the model (a resumed run's
    own); a setup that fails removes a new run folder again."""
    import torch

    a = p.args
    with removed_on_failure(run, made_log_dir, keep=bool(a.resume)), contextlib.ExitStack() as opened:
        command = shlex.join([sys.executable, *sys.argv]) + "\n"
        if a.resume:
            command = (run / "command.txt").read_text() + command
        else:
            write_text(run / "config.yml", yaml.safe_dump(run_config(p), sort_keys=False))
        write_text(run / "command.txt", command)
        torch.set_num_threads(1)
        envs = make_envs(
            p.env_kwargs, p.n_envs, a.seed, p.normalize, p.gamma, run / "monitor",
            subproc=a.vec_env == "subproc", wrapper=p.wrapper, mode=a.action_mode,
        )  # fmt: skip
        opened.callback(envs.close)
        eval_env = make_envs(
            p.env_kwargs, 1, a.seed + 1000, p.normalize, p.gamma, training=False, wrapper=p.wrapper,
            mode=a.action_mode,
        )  # fmt: skip
        opened.callback(eval_env.close)
        if a.resume:
            model = checkpoints.load(run, p.cls, envs)
        else:
            model = p.cls(
                p.hp.get("policy", "MlpPolicy"), envs, seed=a.seed, tensorboard_log=str(run / "tensorboard"),
                device="cpu", verbose=0, **p.model_kwargs,
            )  # fmt: skip
        opened.pop_all()  # set up: the envs stay open for the training
    return envs, eval_env, model


def train(args: argparse.Namespace, on_evaluation: OnEvaluation | None = None) -> pathlib.Path:
    """Train, save and score (unless ``args.final_episodes`` is 0); returns the run folder.
    ``on_evaluation(env steps, mean return)`` sees each periodic evaluation; its False stops the
    training. If the setup fails (an invalid env keyword, an algorithm that refuses its
    hyperparameters, ...), the run folder is removed again before the error propagates; the first
    Ctrl-C saves the resumable state (:mod:`agents.checkpoints`) and raises KeyboardInterrupt."""
    began = time.perf_counter()
    p = plan(args)
    args = p.args
    phases: dict[str, float] = {}  # wall time (s) of each phase of the run
    demonstrations = p.demonstrations
    if p.demo_seed is not None:
        demonstrations = demonstrate(p)
        phases["demonstrations"] = time.perf_counter() - began
    made_log_dir = not pathlib.Path(args.log_dir).exists()
    run = (
        pathlib.Path(args.resume)
        if args.resume
        else run_folder(args.log_dir, args.algo, args.action_mode, args.seed)
    )
    done = checkpoints.steps_done(run) if args.resume else 0
    envs, eval_env, model = set_up(run, p, made_log_dir)
    if demonstrations is not None:
        start = time.perf_counter()
        if p.demo_seed is not None:
            demonstrations.save(run / "demonstrations.npz")
        fit = pretrain(model, envs, demonstrations)
        action, value = fit["action_mse"], fit["value_mse"]
        phases["cloning"] = time.perf_counter() - start
        print(f"pretrained on {len(demonstrations.actions)} demonstrated bounces in "
              f"{phases['cloning']:.0f} s: held-back mean squared error of the action {action:.2e}, "
              f"of the value {value:.2e}")  # fmt: skip
    start = time.perf_counter()
    steps = callbacks(run, eval_env, args, p.n_envs, p.total, on_evaluation, demonstrations is not None)
    with checkpoints.CtrlC() as ctrl_c:
        steps += [checkpoints.every(run, args.checkpoint_minutes), ctrl_c.callback()]
        model.learn(total_timesteps=p.total - done, callback=steps, reset_num_timesteps=not args.resume)
    if ctrl_c.requested:
        interrupted(run, model, envs, eval_env)
    wall = phases[args.algo] = time.perf_counter() - start
    finish(run, model, envs, eval_env)
    unit = "bounces" if p.wrapper in TASKS else "env steps"  # a bounce-level task's step is a bounce
    print(f"trained {args.algo} for {model.num_timesteps} {unit} in {wall:.0f} s "
          f"({wall / model.num_timesteps * 1e5:.0f} s per 100k {unit}); run folder {run}")  # fmt: skip
    if args.final_episodes > 0 and is_ball3d(args.action_mode):
        print(f"no scoreboard for the 3-D ball: score the run with  python -m agents.evaluate3d {run}")
    elif args.final_episodes > 0:
        score(run, args, p.env_kwargs, phases, f"{model.num_timesteps} {unit}", began)
    return run


def demonstrate(p: Plan) -> Demonstrations:
    """``--warm-start clone``'s demonstrations: the lookahead playing ``--demo-episodes`` episodes
    of the run's task from ``p.demo_seed`` (training seeds), in one process per core with
    ``--vec-env subproc``."""
    a = p.args
    workers = min(os.cpu_count() or 1, a.demo_episodes) if a.vec_env == "subproc" else 1
    start = time.perf_counter()
    assert p.demo_seed is not None and p.wrapper is not None  # plan checked the task
    seeds = f"{p.demo_seed}..{p.demo_seed + a.demo_episodes - 1}"
    print(f"recording the lookahead's demonstrations of {a.demo_episodes} episodes (seeds {seeds}) in "
          f"{workers} process{'es' if workers > 1 else ''}", flush=True)  # fmt: skip
    demonstrations = record_in_parallel(p.env_kwargs, a.demo_episodes, p.demo_seed, p.wrapper, workers)
    wall = time.perf_counter() - start
    print(f"recorded {len(demonstrations.actions)} demonstrated bounces in {wall:.0f} s")
    return demonstrations


def finish(run: pathlib.Path, model: BaseAlgorithm, envs: VecEnv, eval_env: VecEnv) -> None:
    """Save the final model and normalisation, signed (:mod:`agents.signatures`: evaluation then
    loads them), and close the envs."""
    model.save(run / "model")
    written = [run / "model.zip"]
    if hasattr(envs, "obs_rms"):  # a VecNormalize
        written.append(save_normalization(envs, run / "vecnormalize.npz"))
    sign(written)
    envs.close()
    eval_env.close()


def interrupted(run: pathlib.Path, model: BaseAlgorithm, envs: VecEnv, eval_env: VecEnv) -> None:
    """Save the resumable state of a training stopped by Ctrl-C, say how to go on, and raise
    KeyboardInterrupt."""
    folder = checkpoints.save(run, model, envs)
    envs.close()
    eval_env.close()
    print(f"\ninterrupted at {model.num_timesteps} env steps; the state is saved in {folder}: go on "
          f"with  python train.py --resume {run}", file=sys.stderr)  # fmt: skip
    raise KeyboardInterrupt


def resumed(args: argparse.Namespace) -> tuple[argparse.Namespace, dict[str, Any]]:
    """The arguments and hyperparameters of the run folder ``args.resume``, as it was started
    (``config.yml``); what the command line says of the run itself is ignored."""
    config_path = pathlib.Path(args.resume) / "config.yml"
    if not config_path.exists():
        raise UsageError(f"--resume {args.resume}: no config.yml there (not a run folder of train.py)")
    try:
        checkpoints.steps_done(pathlib.Path(args.resume))
    except ValueError as err:  # no resumable state, or one this user's training did not sign
        raise UsageError(f"--resume {args.resume}: {err}") from None
    config = yaml.safe_load(config_path.read_text())
    hp = {
        **config["hyperparams"], "policy": config["policy"], "normalize": config["normalize"],
        "env_wrapper": config["env_wrapper"], "n_envs": config["n_envs"],
        "n_timesteps": config["total_timesteps"], "env_kwargs": config["env_kwargs"],
    }  # fmt: skip
    mode = mode_of(config.get("env_id", "")) or config["env_kwargs"]["action_mode"]  # 3-D: from the id
    new = argparse.Namespace(**{
        **vars(args), "algo": config["algo"], "action_mode": mode,
        "env_kwargs": config["env_kwargs"], "seed": config["seed"], "n_envs": config["n_envs"],
        "total_timesteps": config["total_timesteps"], "eval_freq": config["eval_freq"],
        "eval_episodes": config["eval_episodes"], "vec_env": config["vec_env"],
        "demonstrations": None, "conf_file": None, "hyperparams": None, "warm_start": "none",
    })  # fmt: skip
    return new, hp


def score(
    run: pathlib.Path,
    args: argparse.Namespace,
    env_kwargs: dict[str, Any],
    phases: dict[str, float],
    trained_for: str,
    began: float,
) -> None:
    """Score the best model and the baselines on the same held-out seeds; write the scoreboard
    (with the reference rows of :mod:`agents.scoreboard`), the learning curve and a clip of the
    trained agent; say what was written, and what was not and why. ``phases``: the wall time (s)
    of the run's phases so far; ``began``: ``time.perf_counter()`` at the run's start."""
    start = time.perf_counter()
    best = run / "best_model.zip"
    policy = best if best.exists() else run / "model.zip"
    specs = [str(policy)] + ([] if args.no_baselines else ["heuristic", "random"])
    scores = [evaluate(s, env_kwargs, args.final_episodes, algo=args.algo, progress=True) for s in specs]
    scores[0] = type(scores[0])(**{**asdict(scores[0]), "policy": f"{args.algo} ({policy.name})"})
    phases["scoring"] = time.perf_counter() - start
    refs = references(args.action_mode, args.algo, pathlib.Path(args.log_dir))
    text = board(scores, refs, DEFAULT_SEED)
    if not args.no_baselines:
        text += "\n\n" + verdict(scores[0], scores[1])
    written: list[pathlib.Path] = []
    missing: list[str] = []
    curve = plot_learning_curve(run, scores, trained_for.split(" ", 1)[1])
    if curve is None:
        missing.append("no learning_curve.png: no periodic evaluation ran (--eval-freq above the budget)")
    else:
        written.append(curve)
    clip, why = record_clip(run / "clip.gif", policy, env_kwargs, args.algo)
    if clip is None:
        missing.append(why)
    else:
        written.append(clip)
    phases["total"] = time.perf_counter() - began
    timing = ", ".join(f"{name} {seconds:.0f} s" for name, seconds in phases.items())
    header = f"{args.algo}, {args.action_mode} mode, {trained_for}, seed {args.seed}; wall time: {timing}\n\n"
    write_text(run / "scores.md", header + text + "\n")
    write_text(run / "scores.json", json.dumps([asdict(s) for s in scores], indent=2))
    print(header + text)
    files = [run / "scores.md", run / "scores.json", *written]
    print(f"wrote {', '.join(str(f) for f in files)}")
    for line in missing:
        print(line)


def record_clip(
    path: pathlib.Path, policy: pathlib.Path, env_kwargs: dict[str, Any], algo: str, seconds: float = 4.0
) -> tuple[pathlib.Path | None, str]:
    """A GIF at ``path`` of the saved model ``policy`` playing the first held-out episode's first
    ``seconds`` (s) of simulated time, every fourth control step (25 frames per second of simulated
    time at 100 Hz control), in real time; ``(path, "")``, or ``(None, why not)`` if Pillow (the
    render extra) is not installed."""
    from ballenv.extras import render_modes

    if "rgb_array" not in render_modes():
        return None, "no clip.gif: the render extra is not installed (pip install 'ballenv[render]')"
    import gymnasium as gym
    from PIL import Image

    from .baselines import make_policy
    from .config import ENV_ID

    env = gym.make(ENV_ID, **env_kwargs, render_mode="rgb_array")
    agent = make_policy(str(policy), env, algo)
    every = 4
    fps = float(env.metadata["render_fps"])
    obs, _ = env.reset(seed=DEFAULT_SEED)
    agent.reset(DEFAULT_SEED)
    frames = []
    for k in range(round(seconds * fps) + 1):
        if k % every == 0:
            frame = env.render()
            assert isinstance(frame, np.ndarray)  # rgb_array
            frames.append(Image.fromarray(frame).quantize(colors=64, dither=Image.Dither.NONE))
        obs, _, terminated, truncated, _ = env.step(agent.act(obs))
        if terminated or truncated:
            break
    env.close()
    duration = round(1000 * every / fps)  # ms per frame: real time
    frames[0].save(path, save_all=True, append_images=frames[1:], duration=duration, loop=0, optimize=True)
    return path, ""


def plot_learning_curve(
    run: pathlib.Path, scores: Sequence[Score], unit: str = "env steps"
) -> pathlib.Path | None:
    """Mean evaluation return against training steps (``unit``: env steps, or bounces behind a
    bounce-level task), with the baselines' mean returns as lines, in ``run/learning_curve.png``
    (returned); None, and no file, if no periodic evaluation ran."""
    data = run / "evaluations.npz"
    if not data.exists():
        return None
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    log = np.load(data)
    steps, returns = log["timesteps"], log["results"]
    fig, ax = plt.subplots(figsize=(6, 4))
    mean, std = returns.mean(axis=1), returns.std(axis=1)
    ax.plot(steps, mean, "o-", label="trained (periodic evaluation)")
    ax.fill_between(steps, mean - std, mean + std, alpha=0.2)
    for s, color in zip(scores[1:], ("tab:green", "tab:red"), strict=False):
        ax.axhline(s.episode_return, color=color, ls="--", label=f"{s.policy} (held-out episodes)")
    ax.set_xlabel(unit)
    ax.set_ylabel("episode return")
    ax.set_title(run.name)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(run / "learning_curve.png", dpi=120)
    plt.close(fig)
    return run / "learning_curve.png"


if __name__ == "__main__":
    main()
