"""Where numba keeps the simulator's compiled kernels: a folder named by the source it was built from.

numba keys a cached kernel on its own file only: after an edit or an upgrade that changes a function
in another file (a callee it inlined), the old machine code would still load and run. So the cache
of ``ballenv`` lives in a folder named by a hash of every source file of the packages that hold
kernels (``ballenv.physics``, ``ballenv.envs`` and ``ballenv.shell``), numba's version and Python's
(:func:`source_key`): different code, a different folder, never a stale kernel. Inside it a kernel's
files sit at its module's path within the package (:class:`PackageLocator`), not at a hash of the
file's absolute path as numba would put them, so every checkout, clone or install of the same sources
loads the same kernels: only new sources compile. The folder sits under the first writable of
``NUMBA_CACHE_DIR`` (if set), ``$XDG_CACHE_HOME/ballenv/numba`` (by default
``~/.cache/ballenv/numba``, 0700) and a private folder in the system's temporary directory (said
once); with none writable, every run compiles (said once).
Of the folders under the same parent, the ``KEEP`` most recently used are kept, and older ones
removed once unused for ``IDLE`` seconds (a process of another version may still be running
from a folder it opened earlier: its kernels are never deleted under it).

A read-only install can ship its cache: build it with ``NUMBA_CACHE_DIR`` pointing into the install
(run the kernels once, e.g. the test suite), make it read-only, and run with the same setting. numba
only uses a cache folder it can write to, so the kernels of a populated read-only folder of these
sources are copied into the writable folder chosen (said once) and load from there: nothing
recompiles.
"""

import hashlib
import os
import pathlib
import re
import shutil
import sys
import tempfile
import time
from collections.abc import Callable

import numba
from numba.core import caching, config

from .compile_lock import PACKAGE, private_dir, within_package
from .compile_notice import log_info

KERNEL_PACKAGES = ("physics", "envs", "shell")  # where kernels and the constants they freeze are defined
KEEP = 4  # cache folders of other sources kept under one parent
IDLE = 86400.0  # s: a folder beyond those is removed once unused for this long
KEY = re.compile(r"[0-9a-f]{16}")
MOVED = "no writable cache folder in %s: numba's cache of the simulator goes to %s"
SEEDED = "numba's cache of the simulator in %s is read-only: its kernels are copied to %s"
NONE = "no writable folder for numba's cache of the simulator: every run compiles"


try:
    from numba.core.caching import UserProvidedCacheLocator as _UserLocator
except ImportError:  # older numba names it with a leading underscore
    from numba.core.caching import _UserProvidedCacheLocator as _UserLocator  # type: ignore[attr-defined,no-redef]

_LOCATORS = caching.CacheImpl._locator_classes  # numba's locators, tried in order for each function


class PackageLocator(_UserLocator):
    """numba's cache locator for a kernel of this package: its files in ``config.CACHE_DIR`` (the
    folder of these sources, :func:`choose`) under its module's folder relative to the package
    (``physics/step``, ...). numba still checks each file's own stamp before it loads a kernel: a
    hash of the file in numba 0.68; its time and size in older releases, which a new checkout
    changes (there a new checkout compiles)."""

    _ensured: set[str] = set()  # the folders checked so far in this process

    def __init__(self, py_func, py_file):
        super().__init__(py_func, py_file)
        self._cache_path = os.path.join(config.CACHE_DIR, *within_package(py_file).parent.parts)

    def ensure_cache_path(self):
        """numba's check that the kernel's folder exists (made) and takes a new file, once a folder
        per process (numba makes a temporary file for every kernel it loads)."""
        if self._cache_path not in self._ensured:
            super().ensure_cache_path()
            self._ensured.add(self._cache_path)

    @classmethod
    def from_function(cls, py_func, py_file):
        """The locator of ``py_func`` if ``py_file`` lies in this package and a cache folder is
        set, else None (numba's own locators then place it)."""
        if not config.CACHE_DIR or within_package(py_file) is None:
            return None
        return super().from_function(py_func, py_file)


def source_key(package: pathlib.Path = PACKAGE) -> str:
    """16 hex digits of the SHA-256 of the sources (paths and bytes) of ``KERNEL_PACKAGES``, numba's
    version and Python's."""
    digest = hashlib.sha256(f"numba {numba.__version__} python {sys.version_info[:2]}".encode())
    for path in sorted(p for name in KERNEL_PACKAGES for p in (package / name).rglob("*.py")):
        digest.update(path.relative_to(package).as_posix().encode() + b"\0" + path.read_bytes() + b"\0")
    return digest.hexdigest()[:16]


def writable(folder: pathlib.Path) -> bool:
    """Whether ``folder`` exists (made if missing) and a file can be made in it (as numba checks)."""
    try:
        folder.mkdir(mode=0o700, parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=folder):
            return True
    except OSError:
        return False


def parents() -> list[tuple[pathlib.Path, bool]]:
    """The candidate parents of the cache folder, in order, each with whether it must be private."""
    given = os.environ.get("NUMBA_CACHE_DIR")
    home = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    user = os.getuid() if hasattr(os, "getuid") else 0
    temporary = pathlib.Path(tempfile.gettempdir()) / f"ballenv-numba-{user}"
    own = [(pathlib.Path(home) / "ballenv" / "numba", True), (temporary, True)]
    return [(pathlib.Path(given), False), *own] if given else own


def populated(folder: pathlib.Path) -> bool:
    """Whether ``folder`` holds numba cache indexes (``*.nbi``) of compiled kernels."""
    try:
        return any(folder.rglob("*.nbi"))
    except OSError:
        return False


def seed(folder: pathlib.Path, source: pathlib.Path) -> None:
    """Copy the cache files of ``source`` (a read-only cache folder of the same sources) that
    ``folder`` lacks into it; a file that cannot be copied is left to compile."""
    for path in source.rglob("*"):
        target = folder / path.relative_to(source)
        try:
            if path.is_dir():
                target.mkdir(mode=0o700, parents=True, exist_ok=True)
            elif not target.exists():
                shutil.copyfile(path, target)
        except OSError:
            continue


def choose(key: str, is_writable: Callable[[pathlib.Path], bool] = writable) -> str | None:
    """The cache folder for sources of ``key`` (made), or None if no candidate parent is writable."""
    candidates = parents()
    shipped = None  # a populated read-only folder of these sources
    for k, (parent, private) in enumerate(candidates):
        if private and not private_dir(str(parent)):
            continue
        folder = parent / key
        if is_writable(folder):
            if k > 0:
                log_info(MOVED, candidates[0][0], folder)
            if shipped is not None:
                log_info(SEEDED, shipped, folder)
                seed(folder, shipped)
            os.utime(folder)
            prune(parent, folder)
            return str(folder)
        if shipped is None and populated(folder):
            shipped = folder
    log_info(NONE)
    return None


def prune(parent: pathlib.Path, current: pathlib.Path, now: float | None = None) -> None:
    """Remove the cache folders under ``parent`` beyond the ``KEEP`` most recently used that have
    not been used for ``IDLE`` seconds before ``now`` (s since the epoch; default: the clock)."""
    now = time.time() if now is None else now
    try:
        others = [p for p in parent.iterdir() if p != current and p.is_dir() and KEY.fullmatch(p.name)]
        used = sorted(((p.stat().st_mtime, p) for p in others), reverse=True)
    except OSError:
        return
    for mtime, old in used[KEEP:]:
        if now - mtime > IDLE:
            shutil.rmtree(old, ignore_errors=True)


def apply() -> bool:
    """Point numba's cache at the folder of these sources; returns whether kernels are cached."""
    folder = choose(source_key())
    if folder is None:
        return False
    config.CACHE_DIR = folder  # type: ignore[attr-defined]  # (numba sets its settings at import)
    if PackageLocator not in _LOCATORS:
        _LOCATORS.insert(0, PackageLocator)
    return True
