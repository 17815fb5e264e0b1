"""The README's commands install nothing outside ``.venv``; CI installs the viewer test's browser."""

import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parent.parent


@pytest.mark.parametrize("target", ["test", "test-slow"])
def test_make_test_runs_pytest_without_sudo_or_apt_get(target):
    # -n: print the commands without running them; -B: as in a fresh clone (every step out of date)
    dry = subprocess.run(["make", "-n", "-B", target], cwd=ROOT, capture_output=True, text=True, check=True)
    assert "-m pytest -q" in dry.stdout
    assert "sudo" not in dry.stdout and "apt-get" not in dry.stdout


def test_ci_installs_chromium_before_running_the_tests():
    script = ROOT / ".ci" / "run"
    subprocess.run(["bash", "-n", str(script)], check=True)  # parses
    text = script.read_text()
    assert "sudo" not in text  # CI runs as root
    install = text.index("apt-get install -y -qq chromium")
    assert install < text.index("\nmake test")
    assert "WARNING: could not install chromium" in text  # a failed install does not stop CI


def _pip_installs(target):
    """The extras of each ``pip install ... -e '.[...]'`` that ``make -n -B target`` prints."""
    dry = subprocess.run(["make", "-n", "-B", target], cwd=ROOT, capture_output=True, text=True, check=True)
    lines = [line for line in dry.stdout.splitlines() if "pip install" in line and "-e" in line]
    assert all("-c constraints.txt" in line for line in lines), lines  # the pinned set
    return [set(line.split(".[", 1)[1].split("]", 1)[0].split(",")) for line in lines]


def test_make_train_installs_the_train_extra_only_and_make_test_every_extra():
    assert _pip_installs("train") == [{"train"}]
    import tomllib

    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]
    assert _pip_installs("test") == [set(extras)]
    assert any(p.startswith("pillow") for p in extras["train"])  # the run's clip


def test_make_trains_command_is_the_cloned_recipe_and_parses():
    from agents.train import parse_args

    from .benchmark_modules import load_benchmark

    command = load_benchmark("make_train").train_command()
    args = parse_args(command[2:])  # after the Python and train.py
    assert command[1] == "train.py" and args.warm_start == "clone" and args.vec_env == "subproc"
    assert args.final_episodes >= 20  # enough held-out episodes for intervals apart
