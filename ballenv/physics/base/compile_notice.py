"""A notice while numba compiles the simulator (the first run after an install or a code change),
instead of a silent wait: the compiled kernels are cached on disk (``cache=True``), so later runs
load them in about a second.

:func:`install` registers a listener for numba's compile events; it logs the first compilation of
a ``ballenv`` kernel and, when the outermost compile ends, the time it took, at INFO on the logger
``ballenv.physics.base.compile_notice`` (a child of ``ballenv``). Loading from the cache raises no
compile event, so a warm run logs nothing.

Where the lines go follows the application's logging: once it has configured logging (a handler
on the root logger or on ``ballenv``'s), its handlers and levels decide (``logging.basicConfig()``
alone shows WARNING and above, so not these); while it has configured none, they go to stderr as
``ballenv: ...`` lines, as ``logging.lastResort`` does for warnings, so that a new user sees why the
first run waits. ``logging.getLogger("ballenv").setLevel(logging.WARNING)`` silences them either way.
"""

import logging
import sys
import time

from numba.core import event

LOGGER = logging.getLogger(__name__)
NOTICE = (
    "compiling the simulator with numba (%s); once per install, up to a few minutes; "
    "later runs load it from the cache"
)


def _ballenv_level():
    """The level set on this logger or on one of its ``ballenv`` ancestors (the root's not counted);
    ``logging.NOTSET`` if none."""
    logger = LOGGER
    while logger.parent is not None:  # the root logger has no parent
        if logger.level != logging.NOTSET:
            return logger.level
        logger = logger.parent
    return logging.NOTSET


def log_info(message, *args):
    """Log ``message % args`` at INFO: through the application's logging if it has configured any,
    else on stderr (unless a level above INFO is set on ``ballenv``'s loggers)."""
    if LOGGER.hasHandlers():
        LOGGER.info(message, *args)
    elif _ballenv_level() <= logging.INFO:
        print("ballenv: " + message % args, file=sys.stderr, flush=True)


class CompileNotice(event.Listener):
    """Logs the outermost compilations of ``ballenv`` kernels (:func:`log_info`)."""

    def __init__(self):
        self.depth = 0
        self.start = 0.0
        self.name = ""

    def _ours(self, ev):
        dispatcher = ev.data.get("dispatcher") if isinstance(ev.data, dict) else None
        module = getattr(getattr(dispatcher, "py_func", None), "__module__", "") or ""
        return module.split(".")[0] == "ballenv", getattr(dispatcher, "__name__", "?")

    def on_start(self, ev):
        ours, name = self._ours(ev)
        if self.depth == 0 and ours:
            self.start = time.perf_counter()
            self.name = name
            log_info(NOTICE, name)
        if self.depth > 0 or ours:
            self.depth += 1

    def on_end(self, ev):
        if self.depth == 0:
            return
        self.depth -= 1
        if self.depth == 0:
            log_info("compiled %s in %.0f s", self.name, time.perf_counter() - self.start)


_LISTENER = CompileNotice()


def install():
    """Register the notice (once per process; repeated calls change nothing)."""
    if not getattr(install, "done", False):
        event.register("numba:compile", _LISTENER)
        install.done = True
