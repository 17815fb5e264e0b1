"""The distribution: the wheel built from this source tree holds the licence, both packages with
their data files, and console scripts that resolve to callables."""

import importlib.metadata
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
