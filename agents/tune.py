"""Tune with Optuna: the scripted controllers' parameters, or PPO's hyperparameters.

    python -m agents.tune heuristic --action-mode pressure --trials 60
    python -m agents.tune heuristic3d --action-mode paddle --trials 30 --episodes 5 --max-episode-steps 400
    python -m agents.tune heuristic3d --action-mode paddle --trials 30 --episodes 5 --max-episode-steps 400 \
        --env-kwargs '{"target_height_range": [0.7, 0.9], "start_height_range": [0.55, 0.65]}' --dry-run
    python -m agents.tune ppo --action-mode paddle --trials 12 --timesteps 100000 [train.py options]
    python -m agents.tune ppo --trials 12 --ray local --parallel 2     # trials as Ray tasks

Both search with Optuna's TPE sampler (seeded: the same command gives the same trials) on training
seeds; the held-out seeds of ``agents.evaluate`` (10,000 on) stay unseen.

* ``heuristic``: the controller's parameters (:data:`HEURISTIC_SPACE`); objective the mean apex
  error over ``--episodes`` episodes seeded 0, 1, ... of the task the agents train on (the
  ``env_kwargs`` of ``hyperparams/ppo.yml``). The best is written to
  ``agents/hyperparams/heuristic.yml`` under the env id, where ``agents.policies.HeuristicPolicy``
  reads it (``--dry-run``: print it only).
* ``heuristic3d``: the 3-D ball's controller (:data:`HEURISTIC3D_SPACE`; paddle mode:
  ``ballenv.controllers.PaddleDribble3D``); objective the mean combined height-and-spot error of
  ``agents.evaluate3d`` over ``--episodes`` episodes seeded 0, 1, ... of ``--max-episode-steps``
  control steps of the env of ``--env-kwargs`` (default: its own defaults); the first trial is the
  parameters ``heuristic.yml`` holds (if any), so the best is never worse than them on those
  episodes. The best is written to ``heuristic.yml`` under the 3-D env id, where
  ``agents.policies.Heuristic3DPolicy`` reads it.
* ``ppo``: the hyperparameters of :func:`sample_ppo` (the ranges of RL Baselines3 Zoo's PPO
  sampler, narrowed to this budget); each trial trains ``--timesteps`` env steps with
  ``agents.train``, its periodic evaluations (mean return over 5 episodes) feed Optuna's median
  pruner, and the objective is the last one. The trials' table and the best entry (RL Zoo format)
  are written to ``{out}/ppo_{mode}.md`` and ``{out}/ppo_{mode}.yml``.

``--ray local|auto|ADDRESS`` runs the trials as Ray tasks (``ballenv.cluster.run_tasks``)
through Optuna's ask-and-tell interface: ``--parallel`` trials (default: the cluster's CPUs) are
asked, run at once and told in trial order, then the next batch. A task cannot hear the pruner
while it trains, so no trial is pruned there (its evaluations are recorded after it). The sampler
is the same, but it sees fewer finished trials: with the same ``--seed`` the trials equal the serial
search's through TPE's random start-up trials (10 for ``heuristic``, 4 for ``ppo``); from the first
later trial asked while another is still running, they differ (TPE counts the running trials among
the worse ones, Optuna's "constant liar"), and the serial search may prune where this one does not.
"""

from __future__ import annotations

import argparse
import dataclasses
import functools
import json
import pathlib
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
import yaml

if TYPE_CHECKING:
    import optuna

from ballenv.files import write_text

from .config import HEURISTIC_PARAMS, heuristic_table, load_hyperparams, task_env_kwargs, tuned_heuristic3d
from .evaluate import evaluate
from .evaluate3d import evaluate3d
from .policies import Heuristic3DPolicy, HeuristicPolicy
from .train import ROOT, OnEvaluation, add_cluster_argument, compile_once, train
from .train import parse_args as train_args

# name -> (low, high, log scale) of each controller parameter
HEURISTIC_SPACE = {
    "pressure": {
        # where the next apex answers the amplitude (benchmarks/pump_response.py: it rises from -45 %
        # to +30 % of the target as u goes from about 0 to 0.2, saturated outside)
        "landing_height": (0.13, 0.25, False),  # m: pump from this height on the way down
        "gain": (0.05, 2.0, True),  # amplitude per relative apex error
        "bias": (0.0, 0.25, False),  # amplitude on target
        "floor": (-0.3, 0.1, False),  # smallest amplitude
    },
    "paddle": {"retention": (0.5, 0.95, False)},  # fraction of a bounce's energy kept
}
HEURISTIC3D_SPACE = {
    "paddle": {
        "retention": (0.7, 0.99, False),  # fraction of the energy above rest a strike and bounce keep
        "carry": (0.3, 1.0, False),  # fraction of the horizontal velocity a bounce keeps
        "spot_gain": (0.2, 1.5, False),  # share of the offset to the spot covered by the next strike
    },
    "pressure": {
        "landing_height": (0.13, 0.4, False),  # m: pump from this height of the centre on the way down
        "gain": (0.05, 2.0, True),
        "bias": (0.0, 0.5, False),
        "floor": (-0.3, 0.1, False),
    },
}


@dataclasses.dataclass(frozen=True)
class TrialResult:
    """One trial's outcome as plain data (what a Ray task returns): the objective ``value``, the
    user attributes to record and the intermediate values ``(env steps, mean return)`` it reported."""

    value: float
    attrs: dict[str, Any]
    reports: tuple[tuple[int, float], ...] = ()


@dataclasses.dataclass(frozen=True)
class HeuristicTrial:
    """A heuristic trial as plain data: the controller's ``params`` scored on ``episodes`` episodes
    (seeds 0, 1, ...) of the env of ``env_kwargs``."""

    params: dict[str, float]
    episodes: int
    env_kwargs: dict[str, Any]


def sample_heuristic(trial: optuna.Trial, mode: str, space: dict[str, Any] | None = None) -> dict[str, float]:
    """The controller parameters of one trial in action mode ``mode`` (of ``space``, default
    :data:`HEURISTIC_SPACE`)."""
    return {
        name: trial.suggest_float(name, low, high, log=log)
        for name, (low, high, log) in (space or HEURISTIC_SPACE)[mode].items()
    }


def score_heuristic(job: HeuristicTrial) -> TrialResult:
    """The mean apex error of the controller with ``job.params`` (and its success rate)."""
    score = evaluate(lambda env: HeuristicPolicy(env, job.params), job.env_kwargs, job.episodes, seed=0)
    return TrialResult(score.apex_error, {"success_rate": score.success_rate})


def heuristic_objective(
    mode: str, episodes: int, env_kwargs: dict[str, Any]
) -> Callable[[optuna.Trial], float]:
    """Optuna objective: mean apex error of the controller with a trial's parameters on the env of
    ``env_kwargs``."""

    def objective(trial: optuna.Trial) -> float:
        result = score_heuristic(HeuristicTrial(sample_heuristic(trial, mode), episodes, env_kwargs))
        record(trial, result)
        return result.value

    return objective


def record(trial: optuna.Trial, result: TrialResult) -> None:
    """Keep ``result``'s user attributes in ``trial``."""
    for key, value in result.attrs.items():
        trial.set_user_attr(key, value)


def tune_heuristic(args: argparse.Namespace) -> optuna.Study:
    import optuna

    study = optuna.create_study(direction="minimize", sampler=optuna.samplers.TPESampler(seed=args.seed))
    env_kwargs = task_env_kwargs("ppo", args.action_mode)  # the task the agents train on
    if args.cluster is None:
        study.optimize(heuristic_objective(args.action_mode, args.episodes, env_kwargs), n_trials=args.trials)
    else:
        optimize_on_cluster(
            study, lambda t: HeuristicTrial(sample_heuristic(t, args.action_mode), args.episodes, env_kwargs),
            score_heuristic, args, warm=functools.partial(compile_once, env_kwargs),
        )  # fmt: skip
    best = {k: round(float(v), 4) for k, v in study.best_params.items()}
    print(f"best apex error {study.best_value:.4f} over {args.episodes} training episodes: {best}")
    if not args.dry_run:
        from ballenv.envs import ENV_IDS

        write_heuristic(ENV_IDS[args.action_mode], best)
    return study


def write_heuristic(env_id: str, params: dict[str, float]) -> None:
    """Store ``params`` under ``env_id`` in ``hyperparams/heuristic.yml`` (the other entries kept)."""
    table = heuristic_table()
    table[env_id] = params
    header = (
        "# The scripted controllers' parameters, tuned by `python -m agents.tune heuristic` (Optuna\n"
        "# TPE, mean apex error over training seeds) and, for the 3-D ids, `python -m agents.tune\n"
        "# heuristic3d` (the combined height-and-spot error of agents.evaluate3d), one entry per env\n"
        "# id; read by agents.policies.HeuristicPolicy and Heuristic3DPolicy.\n"
    )
    write_text(HEURISTIC_PARAMS, header + yaml.safe_dump(table, sort_keys=True))
    print(f"wrote {HEURISTIC_PARAMS}")


def tune_heuristic3d(args: argparse.Namespace) -> optuna.Study:
    """Tune the 3-D ball's controller (module doc: ``heuristic3d``), serially."""
    import optuna

    from ballenv.envs import BALL3D_ENV_IDS

    study = optuna.create_study(direction="minimize", sampler=optuna.samplers.TPESampler(seed=args.seed))
    task = train_args(args.train_args).env_kwargs or {}  # --env-kwargs, as train.py reads it
    env_kwargs = {**task, "action_mode": args.action_mode, "max_episode_steps": args.max_episode_steps}
    tuned = tuned_heuristic3d(args.action_mode)
    if tuned:
        study.enqueue_trial(tuned)

    def objective(trial: optuna.Trial) -> float:
        params = sample_heuristic(trial, args.action_mode, HEURISTIC3D_SPACE)
        score = evaluate3d(lambda env: Heuristic3DPolicy(env, params), env_kwargs, args.episodes, seed=0)
        trial.set_user_attr("height_error", float(np.mean(score.height_errors)))
        trial.set_user_attr("spot_distance", float(np.mean(score.spot_distances)))
        return float(np.mean(score.combined_errors))

    study.optimize(objective, n_trials=args.trials)
    for t in study.trials:
        print(f"trial {t.number}: combined {t.value:.4f} {t.user_attrs} {t.params}")
    best = {k: round(float(v), 4) for k, v in study.best_params.items()}
    print(f"best combined error {study.best_value:.4f} over {args.episodes} training episodes: {best}")
    if not args.dry_run:
        write_heuristic(BALL3D_ENV_IDS[args.action_mode], best)
    return study


def sample_ppo(trial: optuna.Trial | optuna.trial.FixedTrial) -> dict[str, Any]:
    """PPO hyperparameters of one trial (RL Zoo's sampler, narrowed)."""
    n_steps = trial.suggest_categorical("n_steps", [256, 512, 1024])
    return {
        "n_steps": n_steps,
        "batch_size": trial.suggest_categorical("batch_size", [64, 128, 256]),
        "gamma": trial.suggest_categorical("gamma", [0.98, 0.99, 0.995, 0.998]),
        "gae_lambda": trial.suggest_categorical("gae_lambda", [0.9, 0.95, 0.98, 0.99]),
        "learning_rate": trial.suggest_float("learning_rate", 5e-5, 2e-3, log=True),
        "n_epochs": trial.suggest_categorical("n_epochs", [5, 10, 20]),
        "clip_range": trial.suggest_categorical("clip_range", [0.1, 0.2, 0.3]),
        "ent_coef": trial.suggest_float("ent_coef", 1e-8, 1e-2, log=True),
        "sde_sample_freq": trial.suggest_categorical("sde_sample_freq", [4, 8, 16, 32]),
        "policy_kwargs": {
            "net_arch": [trial.suggest_categorical("width", [64, 128, 256])] * 2,
            "log_std_init": trial.suggest_float("log_std_init", -2.0, 0.0),
        },
    }


def ppo_argv(args: argparse.Namespace, hp: dict[str, Any], number: int) -> tuple[str, ...]:
    """``agents.train``'s command line of trial ``number`` with hyperparameters ``hp``."""
    return (
        "--algo", "ppo", "--action-mode", args.action_mode, "--vec-env", "subproc",
        "--total-timesteps", str(args.timesteps), "--eval-freq", str(args.timesteps // 5),
        "--seed", str(args.seed + number), "--log-dir", str(args.out / f"ppo_{args.action_mode}"),
        "--no-baselines", "--final-episodes", "0", "--hyperparams", json.dumps(hp), *args.train_args,
    )  # fmt: skip


def train_ppo_trial(argv: Sequence[str], on_evaluation: OnEvaluation | None = None) -> TrialResult:
    """Train one PPO trial with ``agents.train``'s command line ``argv``: its last periodic
    evaluation (mean return), its run folder and every evaluation; ``on_evaluation``: as
    ``agents.train.train``'s (it prunes the trial)."""
    run = train(train_args(list(argv)), on_evaluation=on_evaluation)
    log = np.load(run / "evaluations.npz")
    returns = [float(r) for r in log["results"].mean(axis=1)]
    reports = tuple(zip((int(t) for t in log["timesteps"]), returns, strict=True))
    return TrialResult(returns[-1], {"run": str(run)}, reports)


def ppo_objective(args: argparse.Namespace) -> Callable[[optuna.Trial], float]:
    """Optuna objective: train one PPO trial, pruned on its periodic evaluations."""
    import optuna

    def objective(trial: optuna.Trial) -> float:
        result = train_ppo_trial(ppo_argv(args, sample_ppo(trial), trial.number), _reporter(trial))
        record(trial, result)
        if trial.should_prune():
            raise optuna.TrialPruned()
        return result.value

    return objective


def _reporter(trial: optuna.Trial) -> Callable[[int, float], bool]:
    def report(step: int, mean_return: float) -> bool:
        trial.report(mean_return, step)
        return not trial.should_prune()  # False stops the training

    return report


def tune_ppo(args: argparse.Namespace) -> optuna.Study:
    import optuna

    from ballenv.envs import ENV_IDS

    args.out.mkdir(parents=True, exist_ok=True)
    study = optuna.create_study(
        direction="maximize", sampler=optuna.samplers.TPESampler(seed=args.seed, n_startup_trials=4),
        pruner=optuna.pruners.MedianPruner(n_startup_trials=3, n_warmup_steps=args.timesteps // 3),
    )  # fmt: skip
    study.enqueue_trial(_current_ppo(args.action_mode))  # the present file's values first
    if args.cluster is None:
        study.optimize(ppo_objective(args), n_trials=args.trials)
    else:
        warm = functools.partial(compile_once, task_env_kwargs("ppo", args.action_mode))
        optimize_on_cluster(
            study, lambda t: ppo_argv(args, sample_ppo(t), t.number), train_ppo_trial, args, warm
        )
    lines = ["| trial | state | last evaluation return | hyperparameters |", "|---:|---|---:|---|"]
    for t in study.trials:
        value = "" if t.value is None else f"{t.value:.1f}"
        lines.append(f"| {t.number} | {t.state.name.lower()} | {value} | {t.params} |")
    name = args.out / f"ppo_{args.action_mode}"
    write_text(name.with_suffix(".md"), "\n".join(lines) + "\n")
    best = {ENV_IDS[args.action_mode]: sample_ppo(optuna.trial.FixedTrial(study.best_params))}
    write_text(name.with_suffix(".yml"), yaml.safe_dump(best, sort_keys=False))
    print("\n".join(lines))
    print(f"best return {study.best_value:.1f}; wrote {name}.md and {name}.yml")
    return study


def optimize_on_cluster(
    study: optuna.Study,
    make_job: Callable[[optuna.Trial], Any],
    task: Callable[[Any], TrialResult],
    args: argparse.Namespace,
    warm: Callable[[], Any] | None = None,
) -> None:
    """``study.optimize`` with its trials as Ray tasks on ``args.cluster`` (Optuna's ask-and-tell
    interface): ask ``args.parallel`` trials (default: one per CPU of the cluster), run
    ``task(make_job(trial))`` for each, tell their results in trial order; again until
    ``args.trials`` have run. No pruning: a task cannot hear the pruner while it runs (its
    intermediate values are recorded after it). A trial whose task was lost with its worker fails.
    ``warm``: ``ballenv.cluster.run_tasks``'s, run before the first batch."""
    from ballenv.cluster import collect, connect, run_tasks
    from ballenv.extras import optional_module

    started = connect(args.cluster, paths=[str(ROOT)])
    ray = optional_module("ray", "tuning on a Ray cluster", "ray", "ray")
    try:
        size = args.parallel or max(int(ray.cluster_resources().get("CPU", 1)), 1)
        for first in range(0, args.trials, size):
            asked = [study.ask() for _ in range(min(size, args.trials - first))]
            outcomes = run_tasks(
                task, [make_job(t) for t in asked], args.cluster, desc=f"trials from {first}",
                warm=warm if first == 0 else None, paths=[str(ROOT)],
            )  # fmt: skip
            results, _ = collect(outcomes, len(asked))
            for trial, result in zip(asked, results, strict=True):
                tell(study, trial, result)
    finally:
        if started:
            ray.shutdown()


def tell(study: optuna.Study, trial: optuna.Trial, result: TrialResult | None) -> None:
    """Tell ``study`` the ``result`` of ``trial`` (its user attributes and intermediate values
    recorded first); ``None`` (its task was lost) fails the trial."""
    import optuna

    if result is None:
        print(f"trial {trial.number} failed: its task was lost with its worker")
        study.tell(trial, state=optuna.trial.TrialState.FAIL)
        return
    record(trial, result)
    for step, value in result.reports:
        trial.report(value, step)
    study.tell(trial, result.value)


def _current_ppo(mode: str) -> dict[str, Any]:
    """The PPO file's values for ``mode`` as trial parameters (the first trial)."""
    hp = load_hyperparams("ppo", mode)
    keys = ("n_steps", "batch_size", "gamma", "gae_lambda", "learning_rate", "n_epochs", "clip_range")
    params = {k: hp[k] for k in keys}
    params["ent_coef"] = max(float(hp.get("ent_coef", 0.0)), 1e-8)
    params["sde_sample_freq"] = hp.get("sde_sample_freq", 8)
    params["width"] = hp["policy_kwargs"]["net_arch"][0]
    params["log_std_init"] = hp["policy_kwargs"].get("log_std_init", 0.0)
    return params


def build_parser() -> argparse.ArgumentParser:
    """The command line of ``python -m agents.tune`` (arguments it does not know go to agents.train)."""
    p = argparse.ArgumentParser(prog="python -m agents.tune", description=__doc__.split("\n")[0])
    p.add_argument("what", choices=("heuristic", "heuristic3d", "ppo"), help="what to tune")
    p.add_argument("--action-mode", choices=("pressure", "paddle"), default="pressure")
    p.add_argument("--trials", type=int, default=40, help="Optuna trials")
    p.add_argument("--episodes", type=int, default=20, help="heuristic: training episodes per trial")
    p.add_argument("--timesteps", type=int, default=100_000, help="ppo: env steps per trial")
    p.add_argument(
        "--max-episode-steps", type=int, default=300, help="heuristic3d: the episodes' time limit (steps)"
    )
    p.add_argument("--seed", type=int, default=0, help="sampler seed (ppo: trial k trains with seed + k)")
    p.add_argument("--out", type=pathlib.Path, default=pathlib.Path("runs/tune"), help="ppo: output folder")
    p.add_argument("--dry-run", action="store_true", help="heuristic(3d): print the best, do not write it")
    add_cluster_argument(p, "the trials (asked and told in batches, not pruned)")
    p.add_argument(
        "--parallel", type=positive_int, default=None,
        help="with --ray: trials asked and run at once (default: the cluster's CPUs)",
    )  # fmt: skip
    return p


def positive_int(text: str) -> int:
    """An integer >= 1 of the command line (argparse reports its error)."""
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise argparse.ArgumentTypeError(f"{text!r} is invalid: must be an integer >= 1")
    return value


def parse_args(argv: Sequence[str] | None = None) -> argparse.Namespace:
    """The options of ``python -m agents.tune``; the arguments it does not know, for agents.train,
    in ``train_args``."""
    parser = build_parser()
    args, rest = parser.parse_known_args(argv)
    if args.what == "heuristic3d" and args.cluster is not None:
        parser.error("heuristic3d runs its trials one by one: --ray is for heuristic and ppo")
    if args.parallel is not None and args.cluster is None:
        parser.error(f"--parallel {args.parallel} needs --ray (without it the trials run one by one)")
    args.train_args = rest  # ppo: goes to agents.train
    return args


def main(argv: Sequence[str] | None = None) -> None:
    args = parse_args(argv)
    tuners = {"heuristic": tune_heuristic, "heuristic3d": tune_heuristic3d, "ppo": tune_ppo}
    tuners[args.what](args)


if __name__ == "__main__":
    main()
