"""One compilation of a kernel's signature across processes (``ballenv.physics.base.compile_lock``)."""

import json
import os
import subprocess
import sys
import time

from ballenv.physics.base import jit
from ballenv.physics.base.compile_lock import SharedCompile
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
