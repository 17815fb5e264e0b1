"""One compilation of a kernel's signature across processes: processes that first call the same
kernel with the same argument types at the same time (a vector env's subprocesses on a fresh
install, the test workers of ``make test``) compile it once; the others wait, then load it from
numba's on-disk cache.

numba compiles a signature a process has not got in memory unless its disk cache holds it, and it
writes the cache only when that compilation ends; processes that start together all miss the cache
and each compiles the same code (tens of seconds of CPU each, for the simulator's step). Here each
Python-called kernel (:func:`.jit.python_entry`) takes a lock file named after its source file (its
path within the package, as the cache files it: two checkouts of the same sources share the lock),
name and argument types (``filelock``: fcntl/msvcrt, released if the process dies) around numba's
compilation, which looks in the disk cache again first, so a process that waited loads what the
first one wrote. A process that waits longer than ``QUIET_WAIT`` says so (:func:`.compile_notice.log_info`),
once: the first such wait of the process logs one line, later ones nothing (on a warm cache the
lock is held only while another process loads a kernel, a fraction of a second, so workers that
start together wait quietly; on an empty cache one line says why the process waits).

The lock files live in a folder of the user's own (``$XDG_CACHE_HOME/ballenv/compile-locks``, by
default ``~/.cache/ballenv/compile-locks``; ``BALLENV_LOCK_DIR`` overrides it), made with
permissions 0700 and used only if it is a real folder (not a symbolic link) owned by the user, so
another user can neither hold a lock nor plant a link. A process waits at most ``WAIT_LIMIT``
(s) for another's compilation (a stopped process may hold a lock for ever), then compiles on its
own and says so. Where no private lock folder can be had (a read-only home, a foreign owner), the
kernel compiles without a lock, as numba does.
"""

import functools
import hashlib
import os
import pathlib
import stat

from filelock import FileLock, Timeout
from numba.core import config, sigutils
from numba.core.registry import CPUDispatcher

from .compile_notice import log_info

PACKAGE = pathlib.Path(__file__).resolve().parents[2]  # ballenv/
WAIT_LIMIT = 900.0  # s: the longest wait for another process's compilation (a cold step: minutes)
QUIET_WAIT = 3.0  # s: a wait this short is not reported (another process loading from the cache)
WAITING = "waiting for another process compiling the simulator (%s); it then loads from the cache"
GAVE_UP = "waited %.0f s for another process compiling the simulator (%s); compiling it here instead"


@functools.cache  # asked for every kernel of a file, each a resolve of its path
def within_package(path):
    """Source file ``path`` relative to the package's folder, or None if it lies outside it."""
    path = pathlib.Path(path).resolve()
    return path.relative_to(PACKAGE) if PACKAGE in path.parents else None


def lock_dir():
    """The folder of the lock files (see the module doc)."""
    given = os.environ.get("BALLENV_LOCK_DIR")
    if given:
        return given
    cache = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return os.path.join(cache, "ballenv", "compile-locks")


def private_dir(path):
    """``path`` made (0700) if missing; True if it is a real folder owned by this user, never a
    symbolic link, with no access for others."""
    try:
        os.makedirs(path, mode=0o700, exist_ok=True)
        info = os.lstat(path)
    except OSError:
        return False
    if not stat.S_ISDIR(info.st_mode) or stat.S_ISLNK(info.st_mode):
        return False
    if hasattr(os, "getuid") and (info.st_uid != os.getuid() or info.st_mode & 0o077):
        return False
    return True


def lock_path(dispatcher, signature):
    """The lock file of ``dispatcher``'s compilation for ``signature`` (numba types) into numba's
    cache directory (``NUMBA_CACHE_DIR``, or beside the source)."""
    function = dispatcher.py_func
    source = within_package(function.__code__.co_filename) or function.__code__.co_filename
    key = repr((config.CACHE_DIR, str(source), function.__qualname__, signature))
    return os.path.join(lock_dir(), hashlib.sha256(key.encode()).hexdigest()[:32] + ".lock")


class SharedCompile(CPUDispatcher):
    """A dispatcher whose compilation of a signature it has not got in memory holds that signature's
    lock file (see the module doc)."""

    def compile(self, sig):
        args, _ = sigutils.normalize_signature(sig)
        if tuple(args) in self.overloads or not private_dir(lock_dir()):
            return super().compile(sig)
        lock = FileLock(lock_path(self, tuple(args)))
        try:
            held = _acquire(lock, self.py_func.__name__)
        except OSError:
            return super().compile(sig)
        try:
            return super().compile(sig)
        finally:
            if held:
                lock.release()


_said_waiting = False  # whether this process has logged WAITING (it does so once)


def _acquire(lock, name):
    """Take ``lock`` within ``QUIET_WAIT`` s quietly, or after waiting longer for the process that
    holds it (saying so, the first time in this process), at most ``WAIT_LIMIT`` s in all; False if
    it is still held then (this process then compiles without it)."""
    global _said_waiting
    quiet = min(QUIET_WAIT, WAIT_LIMIT)
    try:
        lock.acquire(timeout=quiet)
        return True
    except Timeout:
        if not _said_waiting:
            _said_waiting = True
            log_info(WAITING, name)
    try:
        lock.acquire(timeout=WAIT_LIMIT - quiet)
        return True
    except Timeout:
        log_info(GAVE_UP, WAIT_LIMIT, name)
        return False
