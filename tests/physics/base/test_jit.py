"""Kernels without Python wrappers (``ballenv.physics.base.jit``): compiled code calls them directly,
Python through a twin that has the wrappers and its own cache entry, passing it records by
reference."""

import json
import os
import subprocess
import sys
from typing import NamedTuple

import numpy as np

from ballenv.physics.base import jit
from ballenv.physics.base.record_ref import RecordRef, RecordRefType, reference
from ballenv.physics.walls.self_barrier import point_edge_distance2

CALL_TWICE = """
import json
from ballenv.physics.walls.self_barrier import point_edge_distance2
from ballenv.physics.base.jit import python_entry
assert point_edge_distance2(1.0, 2.0, 0.0, 0.0, 4.0, 0.0) == 4.0
stats = python_entry(point_edge_distance2).stats
print(json.dumps([sum(stats.cache_hits.values()), sum(stats.cache_misses.values())]))
"""


def test_a_kernel_is_compiled_without_wrappers_and_python_calls_its_twin():
    assert isinstance(point_edge_distance2, jit.InnerKernel)
    assert point_edge_distance2.targetoptions["no_cpython_wrapper"]  # what compiled code calls
    assert point_edge_distance2(1.0, 2.0, 0.0, 0.0, 4.0, 0.0) == 4.0  # foot on the segment
    assert point_edge_distance2(-3.0, 4.0, 0.0, 0.0, 4.0, 0.0) == 25.0  # nearest the end a
    twin = jit.python_entry(point_edge_distance2)
    assert twin is jit.python_entry(point_edge_distance2)  # made once
    assert not isinstance(twin, jit.InnerKernel) and "no_cpython_wrapper" not in twin.targetoptions
    assert twin.py_func.__qualname__ == "point_edge_distance2.python"  # its own cache entry
    assert jit.python_entry(twin) is twin


def test_the_twin_is_compiled_once_and_then_loaded_from_the_cache(tmp_path):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path), OPENBLAS_NUM_THREADS="1")
    runs = []  # (cache hits, cache misses) of the twin in each process
    for _ in range(2):
        command = [sys.executable, "-c", CALL_TWICE]
        out = subprocess.run(command, capture_output=True, text=True, env=env, check=True)
        runs.append(tuple(json.loads(out.stdout.strip().splitlines()[-1])))
    assert runs[0] == (0, 1)  # compiled in the first process
    assert runs[1] == (1, 0)  # loaded in the second


class Inner(NamedTuple):
    scale: float


class Record(NamedTuple):
    x: np.ndarray
    inner: Inner


class Named(NamedTuple):
    name: str  # no layout in a RecordRef


@jit.kernel
def _scaled_first(record, factor):
    return record.x[0] * record.inner.scale * factor


def test_python_passes_a_kernel_its_records_by_reference():
    record = Record(np.array([3.0, 4.0]), Inner(0.5))
    assert _scaled_first(record, 2.0) == 3.0
    signatures = jit.python_entry(_scaled_first).signatures
    assert [type(s[0]) for s in signatures] == [RecordRefType]  # the twin took a pointer
    assert jit.by_reference(record) is reference(record)
    other = Record(np.zeros(2), Inner(1.0))
    both = jit.by_reference((record, other))
    assert isinstance(both, tuple) and all(isinstance(r, RecordRef) for r in both)
    assert both[0].record is record and both[1].record is other
    for kept in (Named("a"), (1.0, 2), (), np.zeros(2), 3.0):
        assert jit.by_reference(kept) is kept
