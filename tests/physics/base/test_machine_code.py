"""Machine code only where Python calls (``ballenv.physics.base.machine_code``): a kernel that only
compiled code calls stays LLVM IR, unoptimised as a module, linked into the entry points that call
it, whose modules are optimised once with it; its cache entry is IR that a later caller links."""

import os
import subprocess
import sys

import numpy as np
from numba import types
from numba.core import codegen

from ballenv.physics.base import jit, machine_code
from ballenv.physics.base.cyclic import next_node
from ballenv.physics.base.geometry import polygon_area

SQUARE = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])


def _libraries(dispatcher):
    return [result.library for result in dispatcher.overloads.values()]


def test_the_codegen_makes_lazy_libraries():
    assert codegen.JITCPUCodegen._library_class is machine_code.LazyLibrary


def test_an_inner_kernel_stays_ir_and_its_caller_is_emitted_once_with_it_linked_in():
    assert polygon_area(SQUARE) == 1.0  # Python calls the twin, which calls next_node
    next_node.compile((types.int64, types.int64))  # compiled here, or loaded from the cache as IR
    (callee,) = _libraries(next_node)
    assert callee._deferred and callee._unoptimised  # IR, no module passes, no machine code
    assert callee.get_pointer_to_function("no such wrapper") == 0 and callee._deferred
    (entry,) = _libraries(jit.python_entry(polygon_area))
    assert not entry._deferred and not entry._unoptimised  # optimised and emitted, next_node in it


PASSES = """
from numba.core import codegen
import ballenv.physics.base.jit  # noqa: F401  (installs the lazy library)

optimised = []
module_passes = codegen.CPUCodeLibrary._optimize_final_module


def counted(library):
    optimised.append(library.name)
    module_passes(library)


codegen.CPUCodeLibrary._optimize_final_module = counted
import numpy as np
from ballenv.physics.base.geometry import polygon_area
print(polygon_area(np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]])))
print(len(optimised), optimised[0].split(".")[-1])
"""


def test_the_module_passes_run_once_for_an_entry_point_and_its_callees(tmp_path):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path), OPENBLAS_NUM_THREADS="1")
    run = subprocess.run([sys.executable, "-c", PASSES], env=env, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-2000:]
    # numba's own library runs them for next_node and again for the entry with next_node linked in
    assert run.stdout.split() == ["2.0", "1", "python"]


CALLER = """
import numpy as np
from ballenv.physics.base.cyclic import next_node
from ballenv.physics.base.geometry import polygon_area
print(polygon_area(np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]])))
print(sum(next_node.stats.cache_hits.values()), sum(next_node.stats.cache_misses.values()))
"""


def test_an_inner_kernels_cached_ir_is_linked_by_a_caller_compiled_in_a_later_process(tmp_path):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path), OPENBLAS_NUM_THREADS="1")
    run = {"env": env, "capture_output": True, "text": True, "timeout": 300}
    first = subprocess.run([sys.executable, "-c", CALLER], **run)
    assert first.returncode == 0, first.stderr[-2000:]
    assert first.stdout.split() == ["2.0", "0", "1"]  # next_node compiled (a miss), as IR
    twin = jit.python_entry(polygon_area).py_func.__qualname__
    for index in tmp_path.rglob(f"*{twin}*.nbi"):
        index.unlink()  # the entry point is compiled again; next_node's IR comes from the cache
    second = subprocess.run([sys.executable, "-c", CALLER], **run)
    assert second.returncode == 0, second.stderr[-2000:]
    assert second.stdout.split() == ["2.0", "1", "0"]  # next_node loaded (a hit) and linked
