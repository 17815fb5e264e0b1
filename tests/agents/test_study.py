"""agents.study: the interquartile mean, its two-level bootstrap interval, a tiny study end to end,
serially and on a local Ray cluster."""

import json
import pathlib

import numpy as np
import pytest

from agents.study import bootstrap_iqm, bootstrap_success, build_parser, iqm, main, train_seeds

SHORT = {"max_episode_steps": 60}


def test_iqm_is_the_mean_of_the_middle_half():
    assert iqm([1, 2, 3, 4, 5, 6, 7, 8]) == 4.5  # mean of 3, 4, 5, 6
    assert iqm([100.0, 1.0, 2.0, -100.0]) == 1.5  # the outliers drop out
    values = np.random.default_rng(0).normal(size=400)
    middle = np.sort(values)[100:300]
    assert iqm(values) == pytest.approx(middle.mean(), rel=1e-12)


def test_the_interval_counts_the_spread_between_runs():
    """Two runs whose episodes all score 0 and all score 1: a quarter of the resamples draw run 0
    twice (IQM 0) and a quarter run 1 twice (IQM 1), so the 95 % interval is [0, 1]; resampling
    episodes alone would give a point."""
    runs = [np.zeros(10), np.ones(10)]
    assert bootstrap_iqm(runs) == (0.0, 1.0)
    assert bootstrap_iqm([np.full(10, 0.3)]) == pytest.approx((0.3, 0.3))
    low, high = bootstrap_iqm([np.linspace(0.0, 1.0, 20)] * 3)
    assert low < 0.5 < high and 0.0 <= low and high <= 1.0


def test_the_success_interval_pools_apexes_and_counts_the_spread_between_runs():
    """A run whose every apex succeeds and one whose none does: [0, 1] as for the IQM; episodes of
    one rate give that rate; the pooled share weighs an episode by its apexes."""
    assert bootstrap_success([[4, 4], [0, 0]], [[4, 4], [4, 4]]) == (0.0, 1.0)
    assert bootstrap_success([[3] * 10], [[4] * 10]) == pytest.approx((0.75, 0.75))
    low, high = bootstrap_success([[1, 9] * 10] * 3, [[10, 10] * 10] * 3)
    assert low < 0.5 < high
    low, high = bootstrap_success([[0, 18] * 10], [[2, 18] * 10])  # pooled 0.9, per-episode mean 0.5
    assert 0.5 < low <= 0.9 <= high <= 1.0  # around the pooled share, not the episodes' mean


def test_a_tiny_study_runs_end_to_end(tmp_path, capsys):
    argv = [
        "--seeds", "0", "1", "--episodes", "2", "--out", str(tmp_path), "--env-kwargs", json.dumps(SHORT),
        "--timesteps", "128", "--n-envs", "1", "--eval-freq", "64", "--eval-episodes", "1",
        "--hyperparams", json.dumps({"n_steps": 64, "batch_size": 64, "n_epochs": 1}),
    ]  # fmt: skip
    main(argv)
    rows = json.loads((tmp_path / "ppo_pressure.json").read_text())
    assert [r["policy"] for r in rows] == ["ppo (best model)", "heuristic", "random"]
    assert rows[0]["runs"] == 2 and rows[0]["episodes"] == 4 and rows[1]["episodes"] == 2
    for r in rows:
        assert r["ci"][0] <= r["iqm"] <= r["ci"][1]
        assert r["success_ci"][0] <= r["success"] <= r["success_ci"][1]
    assert (tmp_path / "ppo_pressure.png").stat().st_size > 0
    assert "apex error IQM" in (tmp_path / "ppo_pressure.md").read_text()
    assert "apex error IQM" in capsys.readouterr().out
    mtime = (tmp_path / "ppo_pressure_seed0" / "scores.json").stat().st_mtime
    main(argv)  # resumes: the trained seeds are reused, not trained again
    assert (tmp_path / "ppo_pressure_seed0" / "scores.json").stat().st_mtime == mtime
    assert not (tmp_path / "ppo_pressure_seed0_2").exists()
    argv[argv.index("--episodes") + 1] = "3"
    main(argv)  # more held-out episodes: the trained models are scored again, not trained again
    assert (tmp_path / "ppo_pressure_seed0" / "scores.json").stat().st_mtime == mtime
    stored = json.loads((tmp_path / "ppo_pressure_seed0" / "scores.json").read_text())[0]
    longer = json.loads((tmp_path / "ppo_pressure_seed0" / "heldout_3.json").read_text())
    assert longer["episodes"] == 3 and longer["policy"] == stored["policy"]
    assert longer["episode_apex_errors"][:2] == stored["episode_apex_errors"]  # the same first episodes
    rows = json.loads((tmp_path / "ppo_pressure.json").read_text())
    assert rows[0]["episodes"] == 6 and rows[1]["episodes"] == 3


@pytest.mark.slow  # a minute of PPO on Ray; the serial study above and test_cluster's Ray grid stay
def test_seeds_trained_as_ray_tasks_give_the_serial_results(tmp_path, local_ray):
    """Two seeds with two envs each (one process per env, as the serial run) trained as Ray tasks:
    the same held-out scores, learning curves and table as one after the other in this process."""
    argv = [
        "--seeds", "0", "1", "--episodes", "2", "--env-kwargs", json.dumps(SHORT), "--timesteps", "256",
        "--n-envs", "2", "--eval-freq", "128", "--eval-episodes", "1",
        "--hyperparams", json.dumps({"n_steps": 64, "batch_size": 64, "n_epochs": 1}),
    ]  # fmt: skip
    main([*argv, "--out", str(tmp_path / "serial")])
    main([*argv, "--out", str(tmp_path / "ray"), "--ray", "local"])
    for seed in (0, 1):
        serial, ray = (tmp_path / where / f"ppo_pressure_seed{seed}" for where in ("serial", "ray"))
        scores = [json.loads((run / "scores.json").read_text()) for run in (serial, ray)]
        assert scores[1] == scores[0]
        curves = np.load(serial / "evaluations.npz"), np.load(ray / "evaluations.npz")
        assert curves[0]["timesteps"].size == 2
        np.testing.assert_array_equal(curves[1]["results"], curves[0]["results"])
    rows = [json.loads((tmp_path / where / "ppo_pressure.json").read_text()) for where in ("serial", "ray")]
    assert rows[1] == rows[0] and rows[1][0]["runs"] == 2


def test_a_seed_lost_with_its_worker_is_left_out_and_named(monkeypatch, capsys):
    """Ray gave up on seed 1's task (its worker died on every try): the study goes on with seed 0's
    result and says which seed is missing; with every seed lost there is nothing to compare."""
    import ballenv.cluster
    from ballenv.cluster import TaskLost

    def outcomes(fn, jobs, cluster, **options):
        assert cluster == "auto" and [job.seed for job in jobs] == [0, 1]
        yield 1, TaskLost(1, "WorkerCrashedError: the worker died")
        yield 0, "seed 0's result"

    monkeypatch.setattr(ballenv.cluster, "run_tasks", outcomes)
    args, rest = build_parser().parse_known_args(["--seeds", "0", "1", "--ray", "auto"])
    args.train_args = rest
    assert train_seeds(args, {"action_mode": "pressure"}) == ["seed 0's result"]
    assert (
        "seed 1 left out: its task was lost (WorkerCrashedError: the worker died)" in capsys.readouterr().out
    )
    monkeypatch.setattr(
        ballenv.cluster, "run_tasks", lambda fn, jobs, cluster, **o: iter([(0, TaskLost(0, "x"))])
    )
    args.seeds = [0]
    with pytest.raises(RuntimeError, match=r"every training seed of \[0\] was lost"):
        train_seeds(args, {"action_mode": "pressure"})


def test_an_interrupted_seed_resumes_and_one_without_a_saved_state_is_moved_aside(tmp_path, monkeypatch):
    import agents.study as study

    calls = []
    monkeypatch.setattr(study, "train", lambda args: calls.append(args) or pathlib.Path(args.resume or "new"))
    job = study.SeedJob("ppo", "pressure", 0, 256, 2, tmp_path, {})
    run = tmp_path / "ppo_pressure_seed0"
    (run / "resume").mkdir(parents=True)
    (run / "resume" / "state.json").write_text('{"num_timesteps": 128}')
    assert study.train_seed(job) == run and calls[-1].resume == str(run)
    (run / "resume" / "state.json").unlink()
    study.train_seed(job)
    assert calls[-1].resume is None and calls[-1].seed == 0  # trained again under its own name
    assert (tmp_path / "ppo_pressure_seed0.incomplete").exists() and not run.exists()
    (tmp_path / "ppo_pressure_seed0").mkdir()
    (tmp_path / "ppo_pressure_seed0" / "scores.json").write_text("[]")
    assert study.train_seed(job) == run and len(calls) == 2  # finished: reused
