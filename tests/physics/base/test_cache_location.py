"""Where numba's cache goes: beside the sources, a folder of the user's own in a read-only install,
or nowhere (every run compiles) where nothing is writable; ``NUMBA_CACHE_DIR`` always wins."""

import logging
import pathlib

import pytest
from numba.core import config

from ballenv.physics.base import cache_location


@pytest.fixture
def no_cache_dir(monkeypatch, tmp_path, caplog):
    monkeypatch.setattr(config, "CACHE_DIR", "")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "home-cache"))
    caplog.set_level(logging.INFO, logger="ballenv")
    return tmp_path


def test_a_writable_install_caches_beside_its_sources(no_cache_dir, caplog):
    assert cache_location.choose(no_cache_dir, lambda folder: True) == (True, "")
    assert caplog.text == ""


def test_a_read_only_install_caches_in_the_users_folder_and_says_so(no_cache_dir, caplog):
    package = no_cache_dir / "site-packages" / "ballenv" / "physics"
    cache, folder = cache_location.choose(package, lambda f: f != package and cache_location.writable(f))
    assert cache and pathlib.Path(folder) == no_cache_dir / "home-cache" / "ballenv" / "numba"
    assert "is read-only: numba's cache of the simulator goes to" in caplog.text


def test_with_nothing_writable_every_run_compiles_and_says_so(no_cache_dir, caplog):
    assert cache_location.choose(no_cache_dir, lambda folder: False) == (False, "")
    assert "every run compiles" in caplog.text


def test_numba_cache_dir_wins(no_cache_dir, monkeypatch, caplog):
    monkeypatch.setattr(config, "CACHE_DIR", str(no_cache_dir / "given"))
    assert cache_location.choose(no_cache_dir, lambda folder: False) == (True, str(no_cache_dir / "given"))
    assert caplog.text == ""


def test_writable_tells_a_folder_that_takes_files(tmp_path):
    assert cache_location.writable(tmp_path)
    assert not cache_location.writable(tmp_path / "missing")
