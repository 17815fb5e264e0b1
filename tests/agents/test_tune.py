"""agents.tune: the controllers' and PPO's Optuna searches, on tiny budgets, serially and on a local
Ray cluster."""

import ast
import json

import numpy as np
import pytest
import yaml

from agents.config import HEURISTIC_PARAMS, tuned_heuristic, tuned_heuristic3d
from agents.evaluate import evaluate
from agents.policies import HeuristicPolicy
from agents.tune import HEURISTIC3D_SPACE, HEURISTIC_SPACE, main, parse_args, tell, tune_heuristic, tune_ppo

SHORT = {"max_episode_steps": 60}


@pytest.mark.parametrize("mode", ["pressure", "paddle"])
def test_the_heuristic_reads_its_tuned_parameters(mode):
    tuned = tuned_heuristic(mode)
    assert set(tuned) == set(HEURISTIC_SPACE[mode])
    for name, (low, high, _) in HEURISTIC_SPACE[mode].items():
        assert low <= tuned[name] <= high
    kwargs = {"action_mode": mode, "max_episode_steps": 200}
    default = evaluate("heuristic", kwargs, episodes=2)
    explicit = evaluate(lambda env: HeuristicPolicy(env, tuned), kwargs, episodes=2)
    assert default.episode_apex_errors == explicit.episode_apex_errors


def test_heuristic_search_dry_run_leaves_the_file_alone(capsys):
    before = HEURISTIC_PARAMS.read_text()
    main(["heuristic", "--action-mode", "paddle", "--trials", "2", "--episodes", "1", "--dry-run"])
    assert HEURISTIC_PARAMS.read_text() == before
    assert "best apex error" in capsys.readouterr().out


@pytest.mark.parametrize("mode", ["pressure", "paddle"])
def test_the_3d_controllers_tuned_parameters_are_in_range(mode):
    tuned = tuned_heuristic3d(mode)
    assert set(tuned) == set(HEURISTIC3D_SPACE[mode])
    for name, (low, high, _) in HEURISTIC3D_SPACE[mode].items():
        assert low <= tuned[name] <= high


def test_the_3d_heuristic_search_dry_run_scores_trials_and_leaves_the_file_alone(capsys):
    before = HEURISTIC_PARAMS.read_text()
    argv = ["heuristic3d", "--action-mode", "paddle", "--trials", "2", "--episodes", "1"]
    main([*argv, "--max-episode-steps", "40", "--dry-run"])
    assert HEURISTIC_PARAMS.read_text() == before
    out = capsys.readouterr().out
    assert "best combined error" in out and "spot_distance" in out
    with pytest.raises(SystemExit):
        parse_args([*argv, "--ray", "local"])


def test_the_3d_heuristic_search_starts_from_the_tuned_parameters_on_the_task_given(capsys):
    argv = ["heuristic3d", "--action-mode", "paddle", "--trials", "1", "--episodes", "1"]
    argv += ["--max-episode-steps", "40", "--dry-run"]
    main([*argv, "--env-kwargs", json.dumps({"start_height_range": [0.55, 0.65]})])
    best = ast.literal_eval(capsys.readouterr().out.rsplit("training episodes: ", 1)[1].strip())
    assert best == tuned_heuristic3d("paddle")  # the only trial: the file's parameters
    with pytest.raises(ValueError, match="paddle_reach"):  # the keywords reach the env
        main([*argv, "--env-kwargs", json.dumps({"paddle_reach": -1.0})])


def test_ppo_search_trains_trials_and_writes_the_best_in_zoo_format(tmp_path):
    main([
        "ppo", "--trials", "1", "--timesteps", "256", "--out", str(tmp_path), "--n-envs", "1",
        "--env-kwargs", json.dumps(SHORT), "--eval-episodes", "1",
    ])  # fmt: skip
    best = yaml.safe_load((tmp_path / "ppo_pressure.yml").read_text())
    entry = best["InflatedBall-v3"]
    assert entry["n_steps"] in (256, 512, 1024) and np.isfinite(entry["learning_rate"])
    assert "complete" in (tmp_path / "ppo_pressure.md").read_text()
    evaluations = np.load(next((tmp_path / "ppo_pressure").glob("*/evaluations.npz")))
    assert evaluations["timesteps"].size >= 1


@pytest.mark.slow  # 30-55 s of PPO trials; the heuristic's trials on Ray above test the same path
def test_ppo_trials_as_ray_tasks_equal_the_serial_search(tmp_path, local_ray):
    """Two trials (the file's values, then the first sampled) asked together and trained as Ray
    tasks: the same hyperparameters, evaluations and best entry as the serial search."""
    argv = [
        "ppo", "--trials", "2", "--timesteps", "256", "--n-envs", "1", "--env-kwargs", json.dumps(SHORT),
        "--eval-episodes", "1",
    ]  # fmt: skip
    serial = tune_ppo(parse_args([*argv, "--out", str(tmp_path / "serial")]))
    on_ray = ["--out", str(tmp_path / "ray"), "--ray", "local", "--parallel", "2"]
    ray = tune_ppo(parse_args([*argv, *on_ray]))
    assert [t.state.name for t in ray.trials] == ["COMPLETE", "COMPLETE"]
    for a, b in zip(serial.trials, ray.trials, strict=True):
        assert (b.params, b.value, b.intermediate_values) == (a.params, a.value, a.intermediate_values)
        assert len(b.intermediate_values) >= 1 and b.user_attrs["run"].startswith(str(tmp_path / "ray"))
    best = [(tmp_path / where / "ppo_pressure.yml").read_text() for where in ("serial", "ray")]
    assert best[1] == best[0]


def test_heuristic_trials_as_ray_tasks_follow_the_serial_search_through_its_random_start(local_ray):
    """Batches of 2 on a Ray cluster: the 10 random start-up trials of TPE and the first TPE trial
    (asked after them) are those of the serial search; later ones see fewer finished trials."""
    argv = ["heuristic", "--action-mode", "paddle", "--trials", "12", "--episodes", "1", "--dry-run"]
    serial = tune_heuristic(parse_args(argv))
    ray = tune_heuristic(parse_args([*argv, "--ray", "local", "--parallel", "2"]))
    assert len(ray.trials) == 12 and all(t.state.name == "COMPLETE" for t in ray.trials)
    for a, b in zip(serial.trials[:11], ray.trials[:11], strict=True):
        assert (b.params, b.value, b.user_attrs) == (a.params, a.value, a.user_attrs)
    assert ray.best_value == min(t.value for t in ray.trials) and set(ray.best_params) == {"retention"}


def test_a_lost_task_fails_its_trial_and_parallel_needs_a_cluster(capsys):
    import optuna

    study = optuna.create_study()
    tell(study, study.ask(), None)
    assert study.trials[0].state == optuna.trial.TrialState.FAIL
    assert "trial 0 failed: its task was lost" in capsys.readouterr().out
    with pytest.raises(SystemExit):
        parse_args(["heuristic", "--parallel", "2"])
    assert "--parallel 2 needs --ray" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        parse_args(["heuristic", "--ray", "local", "--parallel", "0"])
    assert "'0' is invalid: must be an integer >= 1" in capsys.readouterr().err
