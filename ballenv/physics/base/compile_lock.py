"""One compilation of a kernel's signature across processes: processes that first call the same
kernel with the same argument types at the same time (a vector env's subprocesses on a fresh
install, the test workers of ``make test``) compile it once; the others wait, then load it from
numba's on-disk cache.

numba compiles a signature a process has not got in memory unless its disk cache holds it, and it
writes the cache only when that compilation ends; processes that start together all miss the cache
and each compiles the same code (tens of seconds of CPU each, for the simulator's step). Here each
Python-called kernel (:func:`.jit.python_entry`) takes a lock file named after its source file, name
and argument types (``filelock``: fcntl/msvcrt, released if the process dies) around numba's
compilation, which looks in the disk cache again first, so a process that waited loads what the
first one wrote. A process waiting says so (:func:`.compile_notice.log_info`). Where no lock file can
be made (a read-only temporary directory), the kernel compiles without one.
"""

import hashlib
import os
import tempfile

from filelock import FileLock, Timeout
from numba.core import config, sigutils
from numba.core.registry import CPUDispatcher

from .compile_notice import log_info

USER = os.getuid() if hasattr(os, "getuid") else 0  # one lock directory per user (POSIX)
LOCK_DIR = os.path.join(tempfile.gettempdir(), f"ballenv-compile-{USER}")
WAITING = "waiting for another process compiling the simulator (%s); it then loads from the cache"


def lock_path(dispatcher, signature):
    """The lock file of ``dispatcher``'s compilation for ``signature`` (numba types) into numba's
    cache directory (``NUMBA_CACHE_DIR``, or beside the source)."""
    function = dispatcher.py_func
    key = repr((config.CACHE_DIR, function.__code__.co_filename, function.__qualname__, signature))
    return os.path.join(LOCK_DIR, hashlib.sha256(key.encode()).hexdigest()[:32] + ".lock")


class SharedCompile(CPUDispatcher):
    """A dispatcher whose compilation of a signature it has not got in memory holds that signature's
    lock file (see the module doc)."""

    def compile(self, sig):
        args, _ = sigutils.normalize_signature(sig)
        if tuple(args) in self.overloads:
            return super().compile(sig)
        try:
            os.makedirs(LOCK_DIR, exist_ok=True)
            lock = FileLock(lock_path(self, tuple(args)))
            try:
                lock.acquire(timeout=0)
            except Timeout:
                log_info(WAITING, self.py_func.__name__)
                lock.acquire()
        except OSError:
            return super().compile(sig)
        try:
            return super().compile(sig)
        finally:
            lock.release()
