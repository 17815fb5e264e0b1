"""Compare trained agents with the baselines the rliable way: several training seeds, held-out
episodes, interquartile mean (IQM) with bootstrap confidence intervals, learning curves.

    python -m agents.study --algo ppo --action-mode pressure --seeds 0 1 2 --episodes 20
    python -m agents.study --algo ppo --action-mode paddle --timesteps 400000 --out runs/study
    python -m agents.study --seeds 0 --episodes 2 --env-kwargs '{"max_episode_steps": 60}' \
        --timesteps 512 --n-envs 1 --hyperparams '{"n_steps": 64}'     # train.py options pass through
    python -m agents.study --seeds 0 1 2 3 --ray local      # the seeds as Ray tasks (or auto, host:6379)

Each seed trains with ``agents.train`` into ``{out}/{algo}_{mode}_seed{k}`` (a folder that already
holds ``scores.json`` is reused, so an interrupted study resumes); its best model is scored on the
held-out episodes (seeds 10,000 on), and so are the tuned heuristic and random actions. A later
study with more ``--episodes`` scores the trained models again, without training them. Writes
``{out}/{algo}_{mode}.md`` (the table) and ``{out}/{algo}_{mode}.png`` (learning curves, the
baselines as lines).

With ``--ray``, each seed is one Ray task (``ballenv.cluster.run_tasks``) that trains it and
scores it on the held-out episodes; the baselines are scored here. A task runs its seed as the
serial study does (``--vec-env subproc``: one process per env, torch on one thread), so the same
seeds give the same scores, curves and table. Its run folder is written under ``--out`` on the
machine that ran it (a folder shared by the nodes keeps them all in one place); what the table and
the plot need comes back with the task's result.

Statistics: each episode's apex error (``agents.evaluate``; missed apexes count 1); the IQM is the
mean of the middle 50 % of the episodes pooled over runs; its 95 % interval comes from a stratified
two-level bootstrap (draw runs with replacement, then episodes within each drawn run; 2,000
resamples, percentile interval), so the spread between training seeds counts, as in rliable
(Agarwal et al., 2021, "Deep RL at the edge of the statistical precipice"). rliable itself is not
used: its pin ``arch < 8`` does not import beside pandas 3.
"""

from __future__ import annotations

import argparse
import functools
import json
import pathlib
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ballenv.files import write_text

from . import checkpoints
from .config import parse_env_kwargs, task_env_kwargs
from .evaluate import Score, evaluate
from .train import ROOT, add_cluster_argument, compile_once, parse_args, train

RESAMPLES = 2000


def iqm(values: ArrayLike) -> float:
    """Interquartile mean: the mean of the values between the 25th and 75th percentiles (the
    middle half, by rank; rliable's ``aggregate_iqm``, scipy's ``trim_mean(values, 0.25)``)."""
    v = np.sort(np.asarray(values, dtype=float).ravel())
    cut = int(np.floor(0.25 * v.size))
    return float(v[cut : v.size - cut].mean())


def bootstrap_iqm(
    runs: Sequence[ArrayLike], seed: int = 0, resamples: int = RESAMPLES
) -> tuple[float, float]:
    """95 % percentile interval of the IQM of ``runs`` (a list of per-run arrays of episode scores):
    each resample draws runs with replacement, then episodes with replacement within each."""
    rng = np.random.default_rng(seed)
    runs = [np.asarray(r, dtype=float) for r in runs]
    stats = np.empty(resamples)
    for k in range(resamples):
        picked = rng.integers(len(runs), size=len(runs))
        stats[k] = iqm(np.concatenate([rng.choice(runs[i], size=runs[i].size) for i in picked]))
    low, high = np.percentile(stats, [2.5, 97.5])
    return float(low), float(high)


def bootstrap_success(
    hits: Sequence[ArrayLike], apexes: Sequence[ArrayLike], seed: int = 0, resamples: int = RESAMPLES
) -> tuple[float, float]:
    """95 % percentile interval of the share of apexes within the success tolerance, per run the
    episodes' successful apexes ``hits`` and all their apexes ``apexes``: resampled as
    :func:`bootstrap_iqm` does (runs, then episodes within each), the share of the pooled apexes."""
    rng = np.random.default_rng(seed)
    pairs = [np.column_stack([h, a]).astype(float) for h, a in zip(hits, apexes, strict=True)]
    stats = np.empty(resamples)
    for k in range(resamples):
        picked = rng.integers(len(pairs), size=len(pairs))
        drawn = np.concatenate([pairs[i][rng.integers(len(pairs[i]), size=len(pairs[i]))] for i in picked])
        stats[k] = drawn[:, 0].sum() / max(drawn[:, 1].sum(), 1.0)
    low, high = np.percentile(stats, [2.5, 97.5])
    return float(low), float(high)


def summarise(name: str, scores: Sequence[Score]) -> dict[str, Any]:
    """One table row (a dict) of ``scores``, one :class:`Score` per run (the success interval is
    None for scores stored without their episodes' apexes)."""
    runs = [s.episode_apex_errors for s in scores]
    low, high = bootstrap_iqm(runs)
    counted = all(s.episode_apexes for s in scores)
    success_ci = (
        bootstrap_success([s.episode_successes for s in scores], [s.episode_apexes for s in scores])
        if counted
        else None
    )
    return {
        "policy": name, "runs": len(scores), "episodes": sum(len(r) for r in runs),
        "iqm": iqm(np.concatenate(runs)), "ci": (low, high),
        "mean": float(np.mean(np.concatenate(runs))),
        "success": float(np.mean([s.success_rate for s in scores])), "success_ci": success_ci,
        "return": float(np.mean([s.episode_return for s in scores])),
    }  # fmt: skip


def table(rows: Sequence[dict[str, Any]]) -> str:
    lines = [
        "| policy | runs x episodes | apex error IQM [95 % CI] | apex error mean | apexes within 5 % "
        "[95 % CI] | return |",
        "|---|---:|---:|---:|---:|---:|",
    ]
    for r in rows:
        ci = r.get("success_ci")
        success = f"{100 * r['success']:.1f} %" + (f" [{100 * ci[0]:.1f}, {100 * ci[1]:.1f}]" if ci else "")
        lines.append(
            f"| {r['policy']} | {r['runs']} x {r['episodes'] // r['runs']} | {r['iqm']:.3f} "
            f"[{r['ci'][0]:.3f}, {r['ci'][1]:.3f}] | {r['mean']:.3f} | {success} | {r['return']:.0f} |"
        )
    return "\n".join(lines)


@dataclass(frozen=True)
class SeedJob:
    """One training seed of a study as plain data (a Ray task's argument): train it into ``out``
    unless its folder holds scores, then score its best model on ``episodes`` held-out episodes of
    the env of ``env_kwargs``. ``train_args`` go to ``agents.train`` after the study's own."""

    algo: str
    action_mode: str
    seed: int
    timesteps: int | None
    episodes: int
    out: pathlib.Path
    env_kwargs: dict[str, Any]
    train_args: tuple[str, ...] = ()


@dataclass(frozen=True)
class SeedResult:
    """What a seed's task returns: its run folder (on the machine that trained it), its held-out
    score and its learning curve (the periodic evaluations' env steps and mean returns)."""

    run: pathlib.Path
    score: Score
    steps: NDArray[np.int64]
    returns: NDArray[np.float64]


def run_seed(job: SeedJob) -> SeedResult:
    """Train the seed of ``job`` (or reuse its run), score it on the held-out episodes; one thread
    for torch, as in ``agents.train``, so that the tasks sharing a machine do not oversubscribe it."""
    import torch

    torch.set_num_threads(1)
    run = train_seed(job)
    curve = np.load(run / "evaluations.npz")
    score = heldout_score(job, run)
    return SeedResult(run, score, curve["timesteps"], curve["results"].mean(axis=1))


def train_seed(job: SeedJob) -> pathlib.Path:
    """The run folder of ``job``'s seed, trained now unless it holds scores already: a run that was
    interrupted goes on from its resumable state (``train.py --resume``); one that stopped before
    saving any is moved aside (``.incomplete``) and trained again under its own name."""
    run = job.out / f"{job.algo}_{job.action_mode}_seed{job.seed}"
    if (run / "scores.json").exists():
        return run
    if (run / checkpoints.RESUME / "state.json").exists():
        return train(
            parse_args(["--resume", str(run), "--no-baselines", "--final-episodes", str(job.episodes)])
        )
    if run.exists():
        run.rename(run.with_name(run.name + ".incomplete"))
    argv = [
        "--algo", job.algo, "--action-mode", job.action_mode, "--vec-env", "subproc",
        "--seed", str(job.seed), "--log-dir", str(job.out), "--no-baselines",
        "--final-episodes", str(job.episodes),
    ] + (["--total-timesteps", str(job.timesteps)] if job.timesteps else [])  # fmt: skip
    return train(parse_args(argv + list(job.train_args)))


def heldout_score(job: SeedJob, run: pathlib.Path) -> Score:
    """The best model of ``run`` on ``job.episodes`` held-out episodes: the training's final
    evaluation (``scores.json``) if it has that many and its episodes' apex counts, else a new one
    kept in ``heldout_{n}.json``
    (the same episodes, seeds 10,000 on: a longer evaluation extends the shorter one)."""
    stored = Score(**json.loads((run / "scores.json").read_text())[0])
    if stored.episodes == job.episodes and stored.episode_apexes:  # (a score without them: scored again)
        return stored
    path = run / f"heldout_{job.episodes}.json"
    if not path.exists():
        score = evaluate(run, job.env_kwargs, job.episodes, algo=job.algo, progress=True)
        score = Score(**{**asdict(score), "policy": stored.policy})
        write_text(path, json.dumps(asdict(score), indent=2))
    return Score(**json.loads(path.read_text()))


def train_seeds(args: argparse.Namespace, env_kwargs: dict[str, Any]) -> list[SeedResult]:
    """Every seed of ``args.seeds`` through :func:`run_seed`, one after the other or as Ray tasks
    (``args.cluster``), in seed order. A seed whose task was lost with its worker is reported and
    left out; a RuntimeError if every seed was lost."""
    from ballenv.cluster import collect, run_tasks

    jobs = [
        SeedJob(args.algo, args.action_mode, seed, args.timesteps, args.episodes, args.out, env_kwargs,
                tuple(args.train_args))
        for seed in args.seeds
    ]  # fmt: skip
    outcomes = run_tasks(
        run_seed, jobs, args.cluster, desc="training seeds", warm=functools.partial(compile_once, env_kwargs),
        paths=[str(ROOT)], progress=args.cluster is not None,
    )  # fmt: skip
    results, lost = collect(outcomes, len(jobs))
    for task in lost:
        print(f"seed {jobs[task.index].seed} left out: its task was lost ({task.reason})")
    kept = [r for r in results if r is not None]
    if not kept:
        raise RuntimeError(f"every training seed of {args.seeds} was lost; nothing to compare")
    return kept


def plot(
    path: pathlib.Path, runs: Sequence[SeedResult], baselines: Sequence[dict[str, Any]], title: str
) -> None:
    """Mean periodic-evaluation return over seeds (band: lowest to highest seed) against env steps,
    the baselines' held-out returns as lines."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    steps = runs[0].steps
    n = min(len(r.steps) for r in runs)
    returns = np.array([r.returns[:n] for r in runs])
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(steps[:n], returns.mean(axis=0), "o-", label=f"trained, mean of {len(runs)} seeds")
    ax.fill_between(steps[:n], returns.min(axis=0), returns.max(axis=0), alpha=0.2)
    for row, color in zip(baselines, ("tab:green", "tab:red"), strict=False):
        ax.axhline(row["return"], color=color, ls="--", label=f"{row['policy']} (held-out)")
    ax.set_xlabel("training steps (env steps; bounces behind a bounce-level task)")
    ax.set_ylabel("episode return (periodic evaluation)")
    ax.set_title(title)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def build_parser() -> argparse.ArgumentParser:
    """The command line of ``python -m agents.study`` (arguments it does not know go to agents.train)."""
    p = argparse.ArgumentParser(prog="python -m agents.study", description=__doc__.split("\n")[0])
    p.add_argument("--algo", choices=("ppo", "sac"), default="ppo")
    p.add_argument("--action-mode", choices=("pressure", "paddle"), default="pressure")
    p.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2], help="training seeds")
    p.add_argument("--timesteps", type=int, default=None, help="env steps per run (default: the YAML)")
    p.add_argument("--episodes", type=int, default=20, help="held-out episodes per policy and run")
    p.add_argument("--out", type=pathlib.Path, default=pathlib.Path("runs/study"))
    p.add_argument("--env-kwargs", type=parse_env_kwargs, default={}, help="JSON object of env keywords")
    add_cluster_argument(p, "the training seeds (each trained and scored in one task)")
    return p


def main(argv: Sequence[str] | None = None) -> None:
    args, rest = build_parser().parse_known_args(argv)
    args.train_args = rest  # goes to agents.train
    if args.env_kwargs:
        args.train_args += ["--env-kwargs", json.dumps(args.env_kwargs)]
    mode = task_env_kwargs(args.algo, args.action_mode, args.env_kwargs)  # the YAML's env_kwargs too
    runs = train_seeds(args, mode)
    trained = [r.score for r in runs]
    baselines = [
        summarise(name, [evaluate(name, mode, args.episodes, progress=True)])
        for name in ("heuristic", "random")
    ]
    rows = [summarise(f"{args.algo} (best model)", trained), *baselines]
    name = args.out / f"{args.algo}_{args.action_mode}"
    text = table(rows)
    write_text(name.with_suffix(".md"), text + "\n")
    write_text(name.with_suffix(".json"), json.dumps(rows, indent=2))
    plot(name.with_suffix(".png"), runs, baselines, f"{args.algo}, {args.action_mode} mode")
    print(text)
    print(f"wrote {name}.md, {name}.json and {name}.png")


if __name__ == "__main__":
    main()
