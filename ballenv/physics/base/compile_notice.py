"""A notice while numba compiles the simulator (the first run after an install or a code change),
instead of a silent wait: the compiled kernels are cached on disk (``cache=True``), so later runs
load them in about a second.

:func:`install` registers a listener for numba's compile events. One notice per process, at INFO
on the logger ``ballenv.physics.base.compile_notice`` (a child of ``ballenv``): the first
compilation of a ``ballenv`` kernel says that the simulator is being compiled and why, and when the
process exits, one line says how long the compilation took in all and how many kernels it made.
Each kernel's own time goes to DEBUG. Loading from the cache raises no compile event, so a warm
run logs nothing.

Where the lines go follows the application's logging: once it has configured logging (a handler
on the root logger or on ``ballenv``'s), its handlers and levels decide (``logging.basicConfig()``
alone shows WARNING and above, so not these); while it has configured none, they go to stderr as
``ballenv: ...`` lines, as ``logging.lastResort`` does for warnings, so that a new user sees why the
first run waits. ``logging.getLogger("ballenv").setLevel(logging.WARNING)`` silences them either way.
"""

import atexit
import logging
import sys
import time

from numba.core import event

LOGGER = logging.getLogger(__name__)
NOTICE = (
    "compiling the simulator with numba (the first run after an install or an update; a minute or "
    "more per kind of scene); later runs load it from the cache"
)
DONE = "compiled the simulator in %.0f s (%d %s); later runs load it from the cache"


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
    """Logs that ``ballenv`` kernels are being compiled, once per process (:func:`log_info`), and
    tallies the outermost compilations: ``kernels`` of them, ``spent`` s in all."""

    def __init__(self):
        self.depth = 0
        self.start = 0.0
        self.name = ""
        self.kernels = 0
        self.spent = 0.0

    def _ours(self, ev):
        dispatcher = ev.data.get("dispatcher") if isinstance(ev.data, dict) else None
        module = getattr(getattr(dispatcher, "py_func", None), "__module__", "") or ""
        return module.split(".")[0] == "ballenv", getattr(dispatcher, "__name__", "?")

    def on_start(self, ev):
        ours, name = self._ours(ev)
        if self.depth == 0 and ours:
            self.start = time.perf_counter()
            self.name = name
            if self.kernels == 0:
                log_info(NOTICE)
        if self.depth > 0 or ours:
            self.depth += 1

    def on_end(self, ev):
        if self.depth == 0:
            return
        self.depth -= 1
        if self.depth == 0:
            took = time.perf_counter() - self.start
            self.kernels += 1
            self.spent += took
            LOGGER.debug("compiled %s in %.1f s", self.name, took)

    def summary(self):
        """Log the tally (:data:`DONE`) if anything was compiled, and start a new one."""
        if self.kernels:
            log_info(DONE, self.spent, self.kernels, "kernel" if self.kernels == 1 else "kernels")
        self.kernels, self.spent = 0, 0.0


_LISTENER = CompileNotice()


def install():
    """Register the notice (once per process; repeated calls change nothing)."""
    if not getattr(install, "done", False):
        event.register("numba:compile", _LISTENER)
        atexit.register(_LISTENER.summary)
        install.done = True
