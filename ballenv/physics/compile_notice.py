"""A console notice while numba compiles the simulator (the first run after an install or a code
change), instead of a silent wait: the compiled kernels are cached on disk (``cache=True``), so
later runs load them in about a second.

:func:`install` registers a listener for numba's compile events; it announces the first
compilation of a ``ballenv`` kernel on stderr and reports the time when the outermost compile ends.
Loading from the cache raises no compile event, so a warm run prints nothing.
"""

import sys
import time

from numba.core import event

NOTICE = (
    "ballenv: compiling the simulator with numba ({name}); once per install, about a minute "
    "on two cores; later runs load it from the cache"
)


class CompileNotice(event.Listener):
    """Announces outermost compilations of ``ballenv`` kernels on ``stream``."""

    def __init__(self, stream=None):
        self.stream = stream
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
            print(NOTICE.format(name=name), file=self.stream or sys.stderr, flush=True)
        if self.depth > 0 or ours:
            self.depth += 1

    def on_end(self, ev):
        if self.depth == 0:
            return
        self.depth -= 1
        if self.depth == 0:
            took = time.perf_counter() - self.start
            stream = self.stream or sys.stderr
            print(f"ballenv: compiled {self.name} in {took:.0f} s", file=stream, flush=True)


_LISTENER = CompileNotice()


def install():
    """Register the notice (once per process; repeated calls change nothing)."""
    if not getattr(install, "done", False):
        event.register("numba:compile", _LISTENER)
        install.done = True
