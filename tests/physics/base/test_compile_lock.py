"""One compilation of a kernel's signature across processes (``ballenv.physics.base.compile_lock``)."""

import json
import logging
import os
import pathlib
import stat
import subprocess
import sys
import time

from numba.core import types

from ballenv.physics.base import compile_lock, jit
from ballenv.physics.base.compile_lock import SharedCompile, private_dir
from ballenv.physics.walls.self_barrier import point_edge_distance2

from ..conftest import run_in_two_checkouts

CALL_ON_GO = """
import json, os, sys, time
from ballenv.physics.walls.self_barrier import point_edge_distance2
from ballenv.physics.base.jit import python_entry
open(sys.argv[1] + ".ready", "w").close()
while not os.path.exists(sys.argv[2]):
    time.sleep(1e-3)
assert point_edge_distance2(1.0, 2.0, 0.0, 0.0, 4.0, 0.0) == 4.0
stats = python_entry(point_edge_distance2).stats
print(json.dumps([sum(stats.cache_hits.values()), sum(stats.cache_misses.values())]))
"""


def call(name, go):
    """The command of a process that calls the kernel once the file ``go`` exists."""
    return [sys.executable, "-c", CALL_ON_GO, name, str(go)]


def test_python_calls_a_twin_that_compiles_under_the_lock():
    assert isinstance(jit.python_entry(point_edge_distance2), SharedCompile)


def test_processes_calling_a_new_signature_at_once_compile_it_once(tmp_path):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"), OPENBLAS_NUM_THREADS="1")
    go = tmp_path / "go"
    names = [str(tmp_path / f"process{k}") for k in range(2)]
    processes = [
        subprocess.Popen(call(name, go), stdout=subprocess.PIPE, text=True, env=env) for name in names
    ]
    deadline = time.monotonic() + 120
    while not all(os.path.exists(name + ".ready") for name in names):  # both imported, none compiled
        assert time.monotonic() < deadline and all(p.poll() is None for p in processes)
        time.sleep(0.01)
    go.touch()
    runs = []  # (cache hits, cache misses) of the twin in each process
    for p in processes:
        out, _ = p.communicate(timeout=300)
        assert p.returncode == 0
        runs.append(tuple(json.loads(out.strip().splitlines()[-1])))
    assert sorted(runs) == [(0, 1), (1, 0)]  # one compiled it, the other waited and loaded it


def test_the_lock_folder_is_private_and_never_a_link(tmp_path):
    fresh = tmp_path / "locks"
    assert private_dir(str(fresh))
    assert stat.S_IMODE(fresh.stat().st_mode) == 0o700
    target = tmp_path / "elsewhere"
    target.mkdir(mode=0o700)
    link = tmp_path / "planted"
    link.symlink_to(target)
    assert not private_dir(str(link))  # a link planted by someone else is not followed
    shared = tmp_path / "shared"
    shared.mkdir()
    shared.chmod(0o777)
    assert not private_dir(str(shared))  # others may write there


HOLD_AND_STOP = """
import os, signal, sys
from filelock import FileLock
lock = FileLock(sys.argv[1])
lock.acquire()
print("held", flush=True)
os.kill(os.getpid(), signal.SIGSTOP)  # a compiling process stopped for good
"""


def test_a_stopped_holder_is_waited_for_at_most_the_limit_then_compiled_past(tmp_path, monkeypatch, caplog):
    caplog.set_level(logging.INFO, logger="ballenv")
    monkeypatch.setenv("BALLENV_LOCK_DIR", str(tmp_path / "locks"))
    monkeypatch.setattr(compile_lock, "WAIT_LIMIT", 0.5)
    monkeypatch.setattr(compile_lock, "_said_waiting", False)  # as in a new process
    twin = jit.python_entry(jit.kernel(_scaled))
    assert private_dir(compile_lock.lock_dir())
    path = compile_lock.lock_path(twin, (types.float64,))
    holder = subprocess.Popen([sys.executable, "-c", HOLD_AND_STOP, path], stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "held"
        start = time.monotonic()
        assert twin(2.0) == 6.0
        assert 0.5 <= time.monotonic() - start < 60
    finally:
        holder.kill()
        holder.wait()
    err = caplog.text
    assert "waiting for another process compiling the simulator (_scaled)" in err
    assert "waited 0 s for another process compiling the simulator (_scaled); compiling it here" in err


def _scaled(x):
    return 3.0 * x


HOLD_FOR = """
import sys, time
from filelock import FileLock
locks = [FileLock(path) for path in sys.argv[2:]]
for lock in locks:
    lock.acquire()
print("held", flush=True)
for lock in locks:  # released one after the other, each after the time given
    time.sleep(float(sys.argv[1]))
    lock.release()
"""


def _waits_for(tmp_path, monkeypatch, caplog, seconds, kernels):
    """Call each of ``kernels`` (new twins) while another process holds their locks, releasing one
    every ``seconds``; the log's "waiting" lines."""
    caplog.set_level(logging.INFO, logger="ballenv")
    monkeypatch.setenv("BALLENV_LOCK_DIR", str(tmp_path / "locks"))
    monkeypatch.setattr(compile_lock, "_said_waiting", False)  # as in a new process
    twins = [jit.python_entry(jit.kernel(k)) for k in kernels]
    assert private_dir(compile_lock.lock_dir())
    paths = [compile_lock.lock_path(t, (types.float64,)) for t in twins]
    command = [sys.executable, "-c", HOLD_FOR, str(seconds), *paths]
    holder = subprocess.Popen(command, stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "held"
        assert [t(2.0) for t in twins] == [k(2.0) for k in kernels]
    finally:
        holder.kill()
        holder.wait()
    return [line for line in caplog.text.splitlines() if "waiting for another process" in line]


def test_a_process_says_it_waits_once_however_many_kernels_it_waits_for(tmp_path, monkeypatch, caplog):
    monkeypatch.setattr(compile_lock, "QUIET_WAIT", 0.2)
    lines = _waits_for(tmp_path, monkeypatch, caplog, 1.0, [_doubled, _halved])  # each waits ~1 s
    assert len(lines) == 1 and "(_doubled)" in lines[0], lines


def test_a_short_wait_for_a_process_loading_from_the_cache_is_not_reported(tmp_path, monkeypatch, caplog):
    monkeypatch.setattr(compile_lock, "QUIET_WAIT", 30.0)
    assert _waits_for(tmp_path, monkeypatch, caplog, 0.5, [_negated]) == []


def _doubled(x):
    return 2.0 * x


def _halved(x):
    return 0.5 * x


def _negated(x):
    return -x


LOCK_OF_AREA = """
from numba import types
from ballenv.physics.base import compile_lock, jit
from ballenv.physics.base.geometry import polygon_area
print(compile_lock.lock_path(jit.python_entry(polygon_area), (types.float64[:, ::1],)))
"""


def test_two_checkouts_of_the_same_sources_share_a_kernels_lock(tmp_path):
    # as they share its cache files (cache_location.PackageLocator): one compiles, the other waits
    locks, cache = tmp_path / "locks", str(tmp_path / "cache")
    runs = run_in_two_checkouts(
        tmp_path, LOCK_OF_AREA, compile_lock.PACKAGE, NUMBA_CACHE_DIR=cache, BALLENV_LOCK_DIR=str(locks)
    )
    assert all(run.returncode == 0 for run in runs), runs[-1].stderr[-2000:]
    paths = [run.stdout.strip() for run in runs]
    assert paths[0] == paths[1] and paths[0].startswith(str(locks))
    newton = pathlib.Path("physics", "step", "newton.py")
    assert compile_lock.within_package(compile_lock.PACKAGE / newton) == newton
    assert compile_lock.within_package(tmp_path / "first" / "ballenv" / newton) is None
