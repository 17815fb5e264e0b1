"""numba's cache of the simulator: a folder named by the sources, so an edit or an upgrade never
runs a stale kernel; under the user's cache, a private temporary folder, or nowhere."""

import logging
import os
import pathlib
import shutil
import subprocess
import sys

import pytest

from ballenv.physics.base import cache_location

from ..conftest import run_in_two_checkouts


@pytest.fixture
def homes(monkeypatch, tmp_path, caplog):
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "home-cache"))
    monkeypatch.setattr(cache_location.tempfile, "gettempdir", lambda: str(tmp_path / "tmp"))
    caplog.set_level(logging.INFO, logger="ballenv")
    return tmp_path


def test_the_key_changes_with_any_source_file_and_only_with_the_sources(tmp_path):
    package = tmp_path / "ballenv"
    shutil.copytree(cache_location.PACKAGE, package, ignore=shutil.ignore_patterns("__pycache__"))
    key = cache_location.source_key(package)
    assert key == cache_location.source_key(package) and len(key) == 16
    (package / "README.txt").write_text("not a source")
    (package / "viewer.py").write_text("# no kernel here")
    assert cache_location.source_key(package) == key
    callee = package / "physics" / "base" / "cyclic.py"  # inlined into kernels of other files
    callee.write_text(callee.read_text() + "\n# an edit\n")
    assert cache_location.source_key(package) != key


def test_the_cache_goes_under_the_users_cache_named_by_the_key(homes, caplog):
    folder = pathlib.Path(cache_location.choose("0123456789abcdef"))
    assert folder == homes / "home-cache" / "ballenv" / "numba" / "0123456789abcdef" and folder.is_dir()
    assert caplog.text == ""


def test_numba_cache_dir_is_the_parent_when_set(homes, monkeypatch):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(homes / "given"))
    assert cache_location.choose("0123456789abcdef") == str(homes / "given" / "0123456789abcdef")


def test_a_read_only_home_falls_back_to_a_private_temporary_folder_and_says_so(homes, caplog):
    home = homes / "home-cache" / "ballenv" / "numba"
    folder = cache_location.choose(
        "0123456789abcdef", lambda f: home not in f.parents and cache_location.writable(f)
    )
    assert pathlib.Path(folder).parent.name.startswith("ballenv-numba-")
    assert "numba's cache of the simulator goes to" in caplog.text


def test_with_nothing_writable_every_run_compiles_and_says_so(homes, caplog):
    assert cache_location.choose("0123456789abcdef", lambda folder: False) is None
    assert "every run compiles" in caplog.text


def test_old_cache_folders_beyond_the_most_recent_few_are_removed(homes):
    parent = homes / "home-cache" / "ballenv" / "numba"
    parent.mkdir(parents=True)
    parent.chmod(0o700)  # as the cache makes it
    for k in range(7):
        old = parent / f"{k:016x}"
        old.mkdir()
        os.utime(old, (1000 + k, 1000 + k))
    (parent / "not-a-key").mkdir()
    cache_location.choose("fedcba9876543210")
    kept = sorted(p.name for p in parent.iterdir())
    newest = [f"{k:016x}" for k in (3, 4, 5, 6)]
    assert kept == sorted([*newest, "fedcba9876543210", "not-a-key"])


def test_a_cache_folder_in_recent_use_is_never_removed(homes):
    """Another version's process may still be loading and writing kernels in its folder."""
    parent = homes / "home-cache" / "ballenv" / "numba"
    parent.mkdir(parents=True)
    now = 1e9
    for k in range(7):
        folder = parent / f"{k:016x}"
        folder.mkdir()
        age = cache_location.IDLE * (2.0 if k < 2 else 0.5)  # 0 and 1 idle for two days
        os.utime(folder, (now - age - k, now - age - k))
    cache_location.prune(parent, parent / "fedcba9876543210", now)
    kept = sorted(p.name for p in parent.iterdir())
    assert kept == [f"{k:016x}" for k in range(2, 7)]


AREA = """
import numpy as np
from ballenv.physics.base.geometry import polygon_area
print(polygon_area(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])))
"""


def test_an_edited_callee_in_another_file_is_compiled_again_not_loaded_stale(tmp_path):
    # numba keys polygon_area's cache on geometry.py alone; next_node (cyclic.py) is inlined into it
    package = tmp_path / "checkout" / "ballenv"
    shutil.copytree(cache_location.PACKAGE, package, ignore=shutil.ignore_patterns("__pycache__"))
    env = dict(os.environ, PYTHONPATH=str(package.parent), NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    run = [sys.executable, "-c", AREA]
    first = subprocess.run(run, env=env, capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert first.returncode == 0 and float(first.stdout) == 1.0, first.stderr[-2000:]
    cyclic = package / "physics" / "base" / "cyclic.py"
    cyclic.write_text(cyclic.read_text().replace("return i + 1 if i < n - 1 else 0", "return i"))
    second = subprocess.run(run, env=env, capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert second.returncode == 0 and float(second.stdout) == 0.0, second.stderr[-2000:]  # the new code


HITS = """
from ballenv.physics.base import jit
print(len(jit.python_entry(polygon_area).stats.cache_hits))
"""


def test_two_checkouts_of_the_same_sources_share_their_kernels(tmp_path):
    # the second checkout, elsewhere on the disk, loads what the first compiled
    cache = str(tmp_path / "cache")
    runs = run_in_two_checkouts(tmp_path, AREA + HITS, cache_location.PACKAGE, NUMBA_CACHE_DIR=cache)
    first, second = runs
    assert first.returncode == 0 and first.stdout.split() == ["1.0", "0"], first.stderr[-2000:]
    assert "compiling the simulator" in first.stderr
    assert second.returncode == 0 and second.stdout.split() == ["1.0", "1"], second.stderr[-2000:]
    assert "compiling" not in second.stderr
    folder = tmp_path / "cache" / cache_location.source_key()
    assert (folder / "physics" / "base").is_dir()  # the module's folder within the package


def test_a_populated_read_only_cache_is_copied_to_the_writable_folder(homes, caplog):
    shipped = homes / "install" / "0123456789abcdef"
    (shipped / "physics").mkdir(parents=True)
    (shipped / "physics" / "geometry.polygon_area-9.py311.nbi").write_bytes(b"index")
    (shipped / "physics" / "geometry.polygon_area-9.py311.1.nbc").write_bytes(b"code")
    os.environ["NUMBA_CACHE_DIR"] = str(homes / "install")
    try:
        folder = cache_location.choose(
            "0123456789abcdef", lambda f: shipped not in (f, *f.parents) and cache_location.writable(f)
        )
    finally:
        del os.environ["NUMBA_CACHE_DIR"]
    folder = pathlib.Path(folder)
    assert folder == homes / "home-cache" / "ballenv" / "numba" / "0123456789abcdef"
    assert (folder / "physics" / "geometry.polygon_area-9.py311.1.nbc").read_bytes() == b"code"
    assert "is read-only: its kernels are copied to" in caplog.text


READ_ONLY = """
import pathlib, sys
import numpy as np
from ballenv.physics.base import cache_location, jit
from ballenv.physics.base.geometry import polygon_area
shipped = pathlib.Path(sys.argv[1])  # taken as read-only whoever runs this (root writes anywhere)
writable = cache_location.writable
cache_location.choose.__defaults__ = (lambda f: shipped not in (f, *f.parents) and writable(f),)
assert cache_location.apply()
print(polygon_area(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])))
print(len(jit.python_entry(polygon_area).stats.cache_hits))
"""


def test_a_read_only_install_runs_its_shipped_kernels_without_compiling(tmp_path):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "install"), XDG_CACHE_HOME=str(tmp_path / "home"))
    build = subprocess.run([sys.executable, "-c", AREA], env=env, capture_output=True, text=True, timeout=300)
    assert build.returncode == 0 and "compiling the simulator" in build.stderr, build.stderr[-2000:]
    shipped = tmp_path / "install" / cache_location.source_key()
    run = [sys.executable, "-c", READ_ONLY, str(shipped)]
    second = subprocess.run(run, env=env, capture_output=True, text=True, timeout=300)
    assert second.returncode == 0, second.stderr[-2000:]
    assert second.stdout.split() == ["1.0", "1"]  # the area, loaded from the cache (one hit)
    assert "is read-only: its kernels are copied to" in second.stderr
    assert "compiling" not in second.stderr
    assert (tmp_path / "home" / "ballenv" / "numba" / shipped.name).is_dir()
