"""Work is not lost on Ctrl-C: train.py saves its resumable state (signed) and --resume goes on."""

import json
import pathlib
import signal
import subprocess
import sys
import time

import numpy as np
import yaml

from agents.signatures import signed

ROOT = pathlib.Path(__file__).resolve().parents[2]
TOTAL = 4096  # env steps: more than the test waits for


def command(log_dir, *extra):
    return [
        sys.executable, str(ROOT / "train.py"), "--algo", "ppo", "--seed", "5", "--n-envs", "2",
        "--total-timesteps", str(TOTAL), "--eval-freq", "256", "--eval-episodes", "1",
        "--final-episodes", "1", "--no-baselines", "--log-dir", str(log_dir),
        "--env-kwargs", json.dumps({"max_episode_steps": 60}),
        "--hyperparams", json.dumps({"n_steps": 64, "batch_size": 64, "n_epochs": 1}), *extra,
    ]  # fmt: skip


def test_ctrl_c_saves_a_signed_resumable_state_and_resume_finishes_the_run(tmp_path):
    run = tmp_path / "ppo_pressure_seed5"
    proc = subprocess.Popen(
        command(tmp_path), cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    deadline = time.monotonic() + 300
    while not (run / "evaluations.npz").exists():  # training under way: an evaluation is written
        assert proc.poll() is None and time.monotonic() < deadline
        time.sleep(0.2)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=300)
    assert proc.returncode == 130, err[-3000:]
    assert f"go on with  python train.py --resume {run}" in err
    state = run / "resume"
    done = json.loads((state / "state.json").read_text())["num_timesteps"]
    assert 0 < done < TOTAL
    assert all(signed(state / name) for name in ("model.zip", "vecnormalize.pkl", "state.json"))
    before = np.load(run / "evaluations.npz")["timesteps"]

    # resumed with a shorter budget on the command line: the run's own settings win
    again = [sys.executable, str(ROOT / "train.py"), "--resume", str(run), "--checkpoint-minutes", "0"]
    again += ["--total-timesteps", "512", "--log-dir", str(tmp_path / "elsewhere")]
    resumed = subprocess.run(again, cwd=ROOT, capture_output=True, text=True, timeout=900)
    assert resumed.returncode == 0, resumed.stderr[-3000:]
    assert yaml.safe_load((run / "config.yml").read_text())["total_timesteps"] == TOTAL
    after = np.load(run / "evaluations.npz")["timesteps"]
    assert list(after[: len(before)]) == list(before) and after[-1] >= TOTAL - 512  # the curve goes on
    assert signed(run / "model.zip") and (run / "scores.md").exists()
    assert (run / "command.txt").read_text().count("train.py") == 2
    assert not (tmp_path / "elsewhere").exists()
