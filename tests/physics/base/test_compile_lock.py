"""One compilation of a kernel's signature across processes (``ballenv.physics.base.compile_lock``)."""

import json
import logging
import os
import stat
import subprocess
import sys
import time

from numba.core import types

from ballenv.physics.base import compile_lock, jit
from ballenv.physics.base.compile_lock import SharedCompile, private_dir
from ballenv.physics.walls.self_barrier import point_edge_distance2

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
