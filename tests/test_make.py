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
