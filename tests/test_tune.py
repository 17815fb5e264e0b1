"""agents.tune: the controllers' and PPO's Optuna searches, on tiny budgets."""

import json

import numpy as np
import pytest
import yaml

from agents.baselines import HEURISTIC_PARAMS, HeuristicPolicy, tuned_heuristic
from agents.evaluate import evaluate
from agents.tune import HEURISTIC_SPACE, main

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
