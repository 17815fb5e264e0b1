"""train.py end to end on a tiny budget, and the evaluation command's reproducibility."""

import json
import pathlib
import subprocess
import sys

import numpy as np
import pytest
import yaml

from agents.evaluate import evaluate, main
from agents.train import main as train_main
from agents.train import parse_args, train

ROOT = pathlib.Path(__file__).resolve().parents[2]
SHORT = {"max_episode_steps": 60}  # gym.make's time limit: short episodes for the tests
TINY = {
    "ppo": {"n_steps": 64, "batch_size": 64, "n_epochs": 2},
    "sac": {"learning_starts": 64, "batch_size": 64, "buffer_size": 1000},
}


# each algorithm and each mode once in the default run, the other two pairings in make test-slow
@pytest.mark.parametrize(
    ("algo", "mode"),
    [
        ("ppo", "pressure"),
        ("sac", "paddle"),
        pytest.param("ppo", "paddle", marks=pytest.mark.slow),
        pytest.param("sac", "pressure", marks=pytest.mark.slow),
    ],
)
def test_train_runs_end_to_end_and_the_saved_agent_reloads(algo, mode, tmp_path):
    command = [
        sys.executable, str(ROOT / "train.py"), "--algo", algo, "--action-mode", mode, "--seed", "3",
        "--n-envs", "2", "--total-timesteps", "256", "--eval-freq", "128", "--eval-episodes", "1",
        "--final-episodes", "1", "--log-dir", str(tmp_path), "--env-kwargs", json.dumps(SHORT),
        "--hyperparams", json.dumps(TINY[algo]),
    ]  # fmt: skip
    done = subprocess.run(command, cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    run = tmp_path / f"{algo}_{mode}_seed3"
    saved = ["model.zip", "vecnormalize.npz", "best_model.zip", "best_vecnormalize.npz", "config.yml"]
    saved += ["signatures.json"]
    saved += ["command.txt", "evaluations.npz", "scores.md", "scores.json", "learning_curve.png"]
    for name in saved:
        assert (run / name).exists(), name
    assert any((run / "checkpoints").iterdir())
    assert any((run / "tensorboard").rglob("events.out.tfevents*"))
    config = yaml.safe_load((run / "config.yml").read_text())
    assert config["seed"] == 3 and config["algo"] == algo and config["env_kwargs"]["action_mode"] == mode
    ids = {"pressure": "ballenv:InflatedBall-v3", "paddle": "ballenv:InflatedBallPaddle-v3"}
    assert config["env_id"] == ids[mode]
    assert "--total-timesteps 256" in (run / "command.txt").read_text()
    scores = json.loads((run / "scores.json").read_text())
    assert [s["policy"] for s in scores][1:] == ["heuristic", "random"]
    # the saved model and its normalisation reload and evaluate, from the run folder alone
    again = evaluate(str(run), config["env_kwargs"], episodes=1)
    assert again.apex_error == pytest.approx(scores[0]["apex_error"])
    assert again.episode_length == scores[0]["episode_length"]


@pytest.mark.parametrize("policy", ["random", "heuristic"])
def test_evaluation_gives_the_same_numbers_twice(policy):
    kwargs = {**SHORT, "action_mode": "pressure", "max_episode_steps": 300}
    first = evaluate(policy, kwargs, episodes=3, seed=123)
    second = evaluate(policy, kwargs, episodes=3, seed=123)
    assert first == second
    other = evaluate(policy, kwargs, episodes=3, seed=124)
    assert other != first


def test_evaluate_command_line(tmp_path, capsys):
    out = tmp_path / "score.json"
    main(["heuristic", "--action-mode", "paddle", "--episodes", "2", "--env-kwargs", json.dumps(SHORT),
          "--json", str(out)])  # fmt: skip
    assert "| heuristic | 2 |" in capsys.readouterr().out
    assert json.loads(out.read_text())["episodes"] == 2
    with pytest.raises(SystemExit):
        main(["heuristic", "--env-kwargs", "[1, 2]"])


def test_a_hyperparameter_typo_is_one_readable_line_and_leaves_no_run_folder(tmp_path):
    with pytest.raises(SystemExit) as stop:
        train_main(["--hyperparams", '{"n_step": 64}', "--log-dir", str(tmp_path / "runs")])
    message = str(stop.value.code)
    assert message.startswith("ballenv-train: error: unknown PPO hyperparameter 'n_step'")
    assert "did you mean 'n_steps'?" in message
    assert not (tmp_path / "runs").exists()


def test_a_conf_file_is_read_by_name_or_path_and_a_missing_one_is_named(tmp_path):
    from agents.config import load_hyperparams

    cloned = load_hyperparams("ppo", "paddle", "ppo_cloned")
    assert cloned["env_wrapper"] == "agents.wrappers.PaddleStrike" and cloned["learning_rate"] == 3e-5
    assert load_hyperparams("ppo", "pressure", "ppo_cloned")["env_wrapper"] == "agents.wrappers.PumpApex"
    own = tmp_path / "mine.yml"
    own.write_text("InflatedBall-v3:\n  n_timesteps: 64\n")
    assert load_hyperparams("ppo", "pressure", str(own)) == {"n_timesteps": 64}
    for conf, message in ((str(tmp_path / "none.yml"), "no such file"), (str(own), "no entry for")):
        with pytest.raises(SystemExit) as stop:
            train_main(["--action-mode", "paddle", "--conf-file", conf, "--log-dir", str(tmp_path / "runs")])
        assert (
            message in str(stop.value.code)
            and "ppo_cloned" in str(stop.value.code)
            or message == "no entry for"
        )
    assert not (tmp_path / "runs").exists()


def test_a_mistyped_policy_names_the_choices(capsys):
    choices = "must be one of \\('random', 'heuristic', 'lookahead'\\)"
    with pytest.raises(ValueError, match="policy = 'heuristc' is invalid: " + choices):
        evaluate("heuristc", {"max_episode_steps": 5}, episodes=1)
    with pytest.raises(SystemExit):
        main(["heuristc", "--episodes", "1"])
    assert "policy = 'heuristc' is invalid" in capsys.readouterr().err


def test_a_failed_setup_leaves_no_run_folder(tmp_path):
    runs = tmp_path / "runs"
    quick = ["--total-timesteps", "64", "--final-episodes", "0", "--log-dir", str(runs)]
    # an env keyword the env refuses (the default pressure range bursts a 0.1 MPa wall)
    with pytest.raises(ValueError, match=r"InflatedBall-v3\.pressure_range"):
        train(parse_args(["--env-kwargs", '{"youngs_modulus": 1e5}', *quick]))
    assert not runs.exists()
    # PPO refusing its hyperparameters once the envs are open; an earlier run in runs/ stays
    (runs / "ppo_pressure_seed0").mkdir(parents=True)
    with pytest.raises(AssertionError, match="batch_size"):
        train(parse_args(["--hyperparams", '{"n_steps": 1, "batch_size": 1}', *quick]))
    assert [p.name for p in runs.iterdir()] == ["ppo_pressure_seed0"]


def test_the_task_env_keywords_come_from_the_yaml_and_baselines_are_scored_on_them(monkeypatch):
    import agents.config
    import agents.evaluate

    entry = {"env_kwargs": {"fidelity": "balanced", "reward_margin": 0.1}}
    monkeypatch.setattr(agents.config, "load_hyperparams", lambda algo, mode: entry)
    assert agents.config.task_env_kwargs("ppo", "paddle", {"reward_margin": 0.2}) == {
        "fidelity": "balanced", "reward_margin": 0.2, "action_mode": "paddle",
    }  # fmt: skip
    seen = []

    def record(policy, env_kwargs, *args, **kwargs):
        seen.append(dict(env_kwargs))
        raise SystemExit(0)

    monkeypatch.setattr(agents.evaluate, "evaluate", record)
    with pytest.raises(SystemExit):
        main(["heuristic", "--action-mode", "paddle"])
    assert seen == [{"fidelity": "balanced", "reward_margin": 0.1, "action_mode": "paddle"}]


def test_rl_zoo_linear_schedules_are_read_and_a_malformed_one_is_named():
    from agents.config import UsageError
    from agents.train import schedules

    out = schedules({"learning_rate": "lin_3e-4", "clip_range": 0.2, "gamma": 0.99})
    assert out["learning_rate"](1.0) == pytest.approx(3e-4)
    assert out["learning_rate"](0.25) == pytest.approx(7.5e-5)
    assert out["clip_range"] == 0.2 and out["gamma"] == 0.99
    with pytest.raises(UsageError, match="learning_rate = 'exp_3e-4'"):
        schedules({"learning_rate": "exp_3e-4"})
    with pytest.raises(UsageError, match="clip_range = 'lin_x'"):
        schedules({"clip_range": "lin_x"})


@pytest.fixture(scope="module")
def unevaluated_run(tmp_path_factory):
    """A tiny run whose budget ends before its first periodic evaluation: (run folder, its output)."""
    import contextlib
    import io

    log_dir = tmp_path_factory.mktemp("runs")
    out = io.StringIO()
    args = [
        "--n-envs", "1", "--total-timesteps", "256", "--eval-freq", "100000", "--final-episodes", "1",
        "--no-baselines", "--log-dir", str(log_dir), "--env-kwargs", json.dumps({"max_episode_steps": 150}),
        "--hyperparams", json.dumps({"n_steps": 128, "batch_size": 64, "n_epochs": 1}),
    ]  # fmt: skip
    with contextlib.redirect_stdout(out):
        run = train(parse_args(args))
    return run, out.getvalue()


def test_only_what_was_written_is_said_to_be(unevaluated_run):
    run, out = unevaluated_run
    assert not (run / "evaluations.npz").exists() and not (run / "learning_curve.png").exists()
    wrote = next(line for line in out.splitlines() if line.startswith("wrote "))
    assert "learning_curve.png" not in wrote and "scores.md" in wrote
    assert "no learning_curve.png: no periodic evaluation ran" in out
    for name in wrote.removeprefix("wrote ").split(", "):
        assert pathlib.Path(name).exists(), name


def test_tensorboard_gets_the_task_measures_of_the_training_apexes(unevaluated_run):
    from tensorboard.backend.event_processing.event_accumulator import EventAccumulator

    run, _ = unevaluated_run
    (events,) = (run / "tensorboard").rglob("events.out.tfevents*")
    log = EventAccumulator(str(events.parent))
    log.Reload()
    tags = log.Tags()["scalars"]
    assert {"task/apex_error", "task/success_rate", "task/apexes"} <= set(tags), tags
    errors = [e.value for e in log.Scalars("task/apex_error")]
    shares = [e.value for e in log.Scalars("task/success_rate")]
    assert errors and all(0.0 <= e < 5.0 for e in errors) and all(0.0 <= s <= 1.0 for s in shares)
    assert all(e.value >= 1 for e in log.Scalars("task/apexes"))


def test_warm_start_clone_records_clones_and_scores_with_references_in_one_command(tmp_path):
    args = [
        "--warm-start", "clone", "--demo-episodes", "2", "--n-envs", "1", "--total-timesteps", "8",
        "--eval-freq", "4", "--eval-episodes", "1", "--final-episodes", "2", "--log-dir", str(tmp_path),
        "--env-kwargs", json.dumps({"max_episode_steps": 150}),
        "--hyperparams", json.dumps({"n_steps": 4, "batch_size": 4, "n_epochs": 1}),
    ]  # fmt: skip
    run = train(parse_args(args))
    config = yaml.safe_load((run / "config.yml").read_text())
    assert config["warm_start"] == "clone" and config["env_wrapper"] == "agents.wrappers.PumpApex"
    assert config["demo_seed"] == 5000 and config["demo_episodes"] == 2
    from agents.imitation import Demonstrations

    demonstrations = Demonstrations.load(run / "demonstrations.npz")
    assert demonstrations.ended.sum() == 2  # two episodes
    with np.load(run / "evaluations.npz") as log:
        assert log["timesteps"][0] == 0  # the clone, evaluated before any update
    scores = (run / "scores.md").read_text()
    assert "held-out seeds 10000-10001" in scores
    assert "| reference: lookahead | benchmarks/results/pump_response.md | 1 x 100 |" in scores
    assert any(scores.count(w) for w in ("The trained agent wins", "The tuned heuristic wins", "No winner"))
    assert "wall time: demonstrations" in scores and (run / "clip.gif").exists()


def test_warm_start_clone_refuses_what_it_cannot_clone(tmp_path):
    from agents.config import UsageError

    runs = ["--log-dir", str(tmp_path / "runs")]
    with pytest.raises(UsageError, match="--warm-start clone needs --algo ppo"):
        train(parse_args(["--warm-start", "clone", "--algo", "sac", *runs]))
    with pytest.raises(UsageError, match=r"seeds 9800\.\.10199 must lie in \[0, 10000\)"):
        train(parse_args(["--warm-start", "clone", "--seed", "12", "--demo-episodes", "400", *runs]))
    with pytest.raises(UsageError, match="--demo-episodes = 0 is invalid"):
        train(parse_args(["--warm-start", "clone", "--demo-episodes", "0", *runs]))
    assert not (tmp_path / "runs").exists()
