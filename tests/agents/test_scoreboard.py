"""agents.scoreboard: reference rows read from results files, and the run's verdict."""

import json

from agents.evaluate import Score
from agents.scoreboard import PUMP_RESULTS, board, pump_references, references, study_references, verdict


def _score(policy, mean, half, episodes=30):
    return Score(policy, episodes, mean, half, 0.5, 1000.0, 900.0, 15.0)


def test_the_lookahead_reference_is_read_from_the_pump_results_page():
    rows = {r.policy: r for r in pump_references()}
    assert "heuristic" not in rows and "random" not in rows  # the run scores those itself
    lookahead = rows["lookahead"]
    line = next(x for x in PUMP_RESULTS.read_text().splitlines() if x.startswith("| lookahead |"))
    assert f"| {lookahead.runs} x {lookahead.episodes} |" in line and f"| {lookahead.mean:.3f} |" in line
    assert f"{lookahead.iqm:.3f} [{lookahead.iqm_ci[0]:.3f}, {lookahead.iqm_ci[1]:.3f}]" in line
    assert lookahead.source == "benchmarks/results/pump_response.md"
    assert pump_references(PUMP_RESULTS.with_name("missing.md")) == []


def test_study_tables_under_the_log_folder_are_references(tmp_path):
    rows = [
        {"policy": "ppo (best model)", "runs": 3, "episodes": 300, "iqm": 0.037, "ci": [0.033, 0.04],
         "mean": 0.039, "success": 0.714, "success_ci": None, "return": 958.0},
        {"policy": "heuristic", "runs": 1, "episodes": 100, "iqm": 0.075, "ci": [0.068, 0.082],
         "mean": 0.08, "success": 0.457, "success_ci": None, "return": 896.0},
    ]  # fmt: skip
    (tmp_path / "study_cloned").mkdir()
    (tmp_path / "study_cloned" / "ppo_pressure.json").write_text(json.dumps(rows))
    (tmp_path / "ppo_paddle.json").write_text(json.dumps(rows))  # another mode: not read
    (found,) = study_references(tmp_path, "ppo", "pressure")
    assert found.policy == "ppo (best model), study study_cloned" and (found.runs, found.episodes) == (3, 100)
    assert found.mean == 0.039 and found.iqm_ci == (0.033, 0.04)
    paddle = [r.policy for r in references("paddle", "ppo", tmp_path)]  # no pump page in paddle mode
    assert paddle == [f"ppo (best model), study {tmp_path.name}"]
    text = board([_score("ppo", 0.04, 0.005)], [found], seed=10_000)
    assert "| ppo | this run, held-out seeds 10000-10029 | 1 x 30 | 0.040 [0.035, 0.045] |" in text
    assert "| reference: ppo (best model), study study_cloned |" in text


def test_the_verdict_compares_the_intervals():
    heuristic = _score("heuristic", 0.075, 0.01)
    assert verdict(_score("ppo", 0.04, 0.005), heuristic).startswith("The trained agent wins")
    assert verdict(_score("ppo", 0.07, 0.005), heuristic).startswith("No winner")
    assert verdict(_score("ppo", 0.2, 0.05), heuristic).startswith("The tuned heuristic wins")
