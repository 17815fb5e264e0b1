"""The distribution: the wheel built from this source tree holds the licence, both packages with
their data files, and console scripts that resolve to callables and run once it is installed."""

import importlib
import importlib.metadata
import os
import pathlib
import shutil
import subprocess
import sys
import zipfile

import pytest

ROOT = pathlib.Path(__file__).resolve().parent.parent
SOURCES = ("pyproject.toml", "README.md", "LICENSE", "ballenv", "agents")


@pytest.fixture(scope="module")
def wheel(tmp_path_factory):
    """The wheel of a clean copy of the source tree (no stale ``build/`` folder, no numba caches),
    built without build isolation (about 5 s, no network)."""
    tmp = tmp_path_factory.mktemp("wheel")
    source = tmp / "source"
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc", "*.nbi", "*.nbc")
    for name in SOURCES:
        path = ROOT / name
        if path.is_dir():
            shutil.copytree(path, source / name, ignore=ignore)
        else:
            source.mkdir(exist_ok=True)
            shutil.copy2(path, source / name)
    command = [sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q"]
    done = subprocess.run(
        [*command, str(source), "-w", str(tmp)], capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr[-3000:]
    (built,) = tmp.glob("ballenv-*.whl")
    return zipfile.ZipFile(built)


def dist_info(wheel, name):
    """The text of ``name`` in the wheel's ``.dist-info`` folder."""
    (path,) = [n for n in wheel.namelist() if n.split("/")[0].endswith(".dist-info") and n.endswith(name)]
    return wheel.read(path).decode()


def test_the_wheel_carries_the_mit_licence(wheel):
    metadata = dist_info(wheel, "METADATA")
    assert "License-Expression: MIT" in metadata.splitlines()
    licence = dist_info(wheel, "licenses/LICENSE")
    assert licence.startswith("MIT License") and "Copyright (c)" in licence
    assert licence == (ROOT / "LICENSE").read_text()


def test_the_version_is_written_once_and_the_metadata_reads_it(wheel):
    import ballenv

    metadata = dist_info(wheel, "METADATA")
    assert f"Version: {ballenv.__version__}" in metadata.splitlines()
    assert pathlib.Path(wheel.filename).name.startswith(f"ballenv-{ballenv.__version__}-")
    # the installed distribution (here the editable install of the development environment)
    assert importlib.metadata.version("ballenv") == ballenv.__version__


def test_the_wheel_marks_ballenv_as_typed(wheel):
    assert "ballenv/py.typed" in wheel.namelist()


def test_the_wheel_holds_the_3d_viewers_assets_and_three_js_licence(wheel):
    names = set(wheel.namelist())
    for name in (
        "viewer3d.js",
        "three/three-orbit.min.js",
        "three/LICENSE",
        "three/VERSION",
        "three/README.md",
    ):
        assert f"ballenv/assets/{name}" in names, name
    licence = wheel.read("ballenv/assets/three/LICENSE").decode()
    assert licence.startswith("The MIT License") and "three.js authors" in licence
    assert wheel.read("ballenv/assets/three/VERSION").decode().strip() == "0.187.0"


def test_the_wheel_holds_every_module_and_the_hyperparameter_files(wheel):
    names = set(wheel.namelist())
    for package in ("ballenv", "agents"):
        for path in (ROOT / package).rglob("*"):
            if path.suffix in (".py", ".yml"):
                assert path.relative_to(ROOT).as_posix() in names
    for algo in ("ppo", "sac", "heuristic"):
        assert f"agents/hyperparams/{algo}.yml" in names


def console_scripts(wheel):
    """name -> "module:function" of the wheel's console scripts."""
    section, scripts = None, {}
    for line in dist_info(wheel, "entry_points.txt").splitlines():
        if line.startswith("["):
            section = line.strip("[]")
        elif section == "console_scripts" and "=" in line:
            name, target = (part.strip() for part in line.split("=", 1))
            scripts[name] = target
    return scripts


def test_the_console_scripts_resolve_and_answer_help(wheel, capsys):
    scripts = console_scripts(wheel)
    assert set(scripts) == {
        "ballenv-train",
        "ballenv-evaluate",
        "ballenv-scenes",
        "ballenv-viewer",
        "ballenv-viewer3d",
        "ballenv-compile",
    }
    for name, target in scripts.items():
        module, function = target.split(":")
        main = getattr(importlib.import_module(module), function)
        with pytest.raises(SystemExit) as stop:
            main(["--help"])
        assert stop.value.code == 0, name
        assert capsys.readouterr().out.startswith("usage:"), name


def test_the_installed_wheel_runs_its_console_scripts_from_another_directory(wheel, tmp_path):
    # installed with pip (its dependencies are this environment's), then run from a folder that is
    # not the checkout: ballenv and agents must come from the installation, not from the source tree
    target = tmp_path / "site"
    install = [sys.executable, "-m", "pip", "install", "--no-deps", "-q", "--target", str(target)]
    done = subprocess.run([*install, wheel.filename], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-3000:]
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    env = {**os.environ, "PYTHONPATH": str(target)}
    where = "import ballenv, agents.train; print(ballenv.__file__); print(agents.train.__file__)"
    found = subprocess.run(
        [sys.executable, "-c", where], cwd=elsewhere, env=env, capture_output=True, text=True
    )
    assert found.returncode == 0, found.stderr[-3000:]
    assert all(pathlib.Path(p).is_relative_to(target) for p in found.stdout.split()), found.stdout
    for name in ("ballenv-train", "ballenv-evaluate", "ballenv-scenes", "ballenv-viewer", "ballenv-viewer3d"):
        run = subprocess.run(
            [target / "bin" / name, "--help"], cwd=elsewhere, env=env, capture_output=True, text=True
        )
        assert run.returncode == 0, (name, run.stderr[-3000:])
        assert run.stdout.startswith("usage:"), name
