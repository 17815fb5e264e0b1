"""The compile notice goes through logging: the application's handlers and levels when it has
configured logging, stderr when it has configured none."""

import logging
import pathlib
import subprocess
import sys

import numba

import ballenv.physics  # noqa: F401  (installs the notice)
from ballenv.physics.base import compile_notice

ROOT = pathlib.Path(__file__).resolve().parents[3]
NOTICE_LOGGER = "ballenv.physics.base.compile_notice"


def _fresh_kernel(module):
    """A new numba function that looks defined in ``module`` (compiled at its first call)."""

    def add_one(x):
        return x + 1.0

    add_one.__module__ = module
    return numba.njit(add_one)


def test_compiles_of_ballenv_code_give_one_notice_and_one_tally(caplog):
    listener = compile_notice._LISTENER
    listener.summary()  # (a tally of earlier tests' compiles, if any)
    caplog.set_level(logging.INFO, logger="ballenv")
    assert _fresh_kernel("ballenv.physics.example")(1.0) == 2.0
    assert _fresh_kernel("ballenv.physics.other")(2.0) == 3.0
    records = [(r.name, r.levelno, r.getMessage()) for r in caplog.records]
    assert records == [(NOTICE_LOGGER, logging.INFO, compile_notice.NOTICE)]  # one line for both
    assert listener.kernels == 2 and listener.spent > 0.0
    caplog.clear()
    listener.summary()  # (what the process does at exit)
    (line,) = [r.getMessage() for r in caplog.records]
    assert line.startswith("compiled the simulator in ") and "(2 kernels)" in line


def test_other_compiles_and_levels_above_info_log_nothing(caplog):
    caplog.set_level(logging.INFO, logger="ballenv")
    _fresh_kernel("someone_else")(1.0)
    caplog.set_level(logging.WARNING, logger="ballenv")
    _fresh_kernel("ballenv.physics.example")(1.0)
    assert caplog.records == []


COMPILE = (
    "import ballenv.physics, numba\n"
    "def add_one(x):\n    return x + 1.0\n"
    "add_one.__module__ = 'ballenv.physics.example'\n"
    "numba.njit(add_one)(1.0)\n"
)


def _stderr_of(setup):
    """stderr of a fresh interpreter that runs ``setup`` and then compiles a ballenv kernel."""
    done = subprocess.run(
        [sys.executable, "-c", setup + COMPILE], cwd=ROOT, capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr[-2000:]
    return done.stderr.splitlines()


def test_a_new_user_sees_it_on_stderr_and_a_configured_application_decides():
    # no logging configured: "ballenv: ..." lines on stderr (at INFO, where logging's last resort
    # would show only warnings)
    lines = _stderr_of("")
    assert lines[0] == "ballenv: " + compile_notice.NOTICE
    assert lines[1].startswith("ballenv: compiled the simulator in ") and lines[1].endswith(
        "(1 kernel); later runs load it from the cache"
    )  # at exit
    assert len(lines) == 2
    # configured at INFO: through the application's handler and format
    lines = _stderr_of("import logging; logging.basicConfig(level=logging.INFO)\n")
    assert lines[0].startswith(f"INFO:{NOTICE_LOGGER}:compiling the simulator with numba")
    assert len([line for line in lines if "compil" in line]) == 2
    # configured at WARNING (basicConfig's default), or ballenv's logger silenced: nothing
    assert _stderr_of("import logging; logging.basicConfig()\n") == []
    assert _stderr_of("import logging; logging.getLogger('ballenv').setLevel(logging.WARNING)\n") == []
