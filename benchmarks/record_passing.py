"""What passing a record of arrays costs numba's compiler: a NamedTuple (numba's default, passed by
value: every array's data pointer, shape and strides become arguments of every call) against a
StructRef (``numba.experimental.structref``: one pointer, in numba's reference-counted runtime) and
the package's ``RecordRef`` (``ballenv/physics/base/record_ref.py``: one pointer, no runtime),
through the same chain of compiled functions.

The chain has ``DEPTH`` functions, none inlined; each reads two arrays of the record, writes one and
calls the next twice, as the simulator's kernels pass their records (``ShellStep``, ``Work``, the
ring's ``Model``) down their calls. As the package's kernels, every function but the first is
compiled without Python wrappers and, but for the StructRef's, without reference counting. Each
row is a new process with an empty numba cache (``NUMBA_CACHE_DIR``): its compile time is the
first call's wall time (s), its call time the mean of later calls (us; the chain makes
``2^DEPTH - 1`` calls). Both references' kernels load from numba's cache like any other (the page
checks it: a second process, the same cache, no compile).

    python benchmarks/record_passing.py      # writes benchmarks/results/record_passing.md
"""

import argparse
import json
import os
import pathlib
import subprocess
import sys
import tempfile

from ballenv.files import write_text

RESULTS = pathlib.Path(__file__).parent / "results"
DEPTH = 12  # functions in the chain
SIZES = (10, 30, 60, 120)  # arrays in the record
KINDS = ("NamedTuple", "StructRef", "RecordRef")
CALLS = 2000
CHAIN = """
import json, pathlib, sys, time
import numpy as np

kind, n, depth, calls = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
names = [f"a{i}" for i in range(n)]
lines = ["from collections import namedtuple", "from numba import njit, types",
         "from numba.experimental import structref", f"NAMES = {names!r}"]
if kind != "StructRef":
    lines += ["Record = namedtuple('Record', NAMES)"]
else:
    lines += ["@structref.register", "class RecordType(types.StructRef):",
              "    def preprocess_fields(self, fields):",
              "        return tuple((name, types.unliteral(t)) for name, t in fields)",
              "class Record(structref.StructRefProxy):", "    pass",
              "structref.define_proxy(Record, RecordType, NAMES)"]
for d in range(depth - 1, -1, -1):
    wrappers = "" if d == 0 else ", no_cpython_wrapper=True, no_cfunc_wrapper=True"
    lines += [f"@njit(cache=True, _nrt={kind == 'StructRef'}{wrappers})", f"def f{d}(r, x):",
              f"    s = r.a{d % n}[0] + r.a{(7 * d + 3) % n}[1]",
              f"    r.a{(5 * d + 1) % n}[2] += s"]
    if d < depth - 1:
        lines += [f"    s += f{d + 1}(r, x)", f"    s += f{d + 1}(r, 0.5 * x)"]
    lines += ["    return s + x"]
module = pathlib.Path("chain.py")
if not module.exists():
    module.write_text("\\n".join(lines) + "\\n")
sys.path.insert(0, ".")
import chain

record = chain.Record(*[np.zeros(3) for _ in names])
if kind == "RecordRef":
    from ballenv.physics.base.record_ref import RecordRef
    record = RecordRef(record)
start = time.perf_counter()
chain.f0(record, 1.0)
first = time.perf_counter() - start
start = time.perf_counter()
for _ in range(calls):
    chain.f0(record, 1.0)
call = (time.perf_counter() - start) / calls
print(json.dumps({"first": first, "call": call, "hits": sum(chain.f0.stats.cache_hits.values())}))
"""


def measure(kind: str, n: int, work: str) -> dict:
    """A new process's first call (s), mean later call (s) and cache hits of the chain with a
    record ``kind`` of ``n`` arrays, its module and numba's cache in the folder ``work``."""
    env = {**os.environ, "NUMBA_CACHE_DIR": os.path.join(work, "cache")}
    args = [sys.executable, "-c", CHAIN, kind, str(n), str(DEPTH), str(CALLS)]
    out = subprocess.run(args, env=env, cwd=work, capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def rows() -> list[dict]:
    """Every size and kind on an empty cache, then again in a second process on the filled cache."""
    out = []
    for n in SIZES:
        row: dict = {"n": n}
        for kind in KINDS:
            with tempfile.TemporaryDirectory() as work:
                row[kind] = measure(kind, n, work)
                row[kind + " cached"] = measure(kind, n, work)
        out.append(row)
    return out


def page(results: list[dict]) -> str:
    name = pathlib.Path(__file__).relative_to(pathlib.Path(__file__).parents[1])
    head = (
        "| arrays in the record | compile (s): NamedTuple | StructRef | RecordRef "
        "| NamedTuple over RecordRef | call (us): NamedTuple | StructRef | RecordRef "
        "| second process: compiled (s), cache hits |\n|---:|---:|---:|---:|---:|---:|---:|---:|---|\n"
    )
    body = "".join(
        f"| {r['n']} | "
        + " | ".join(f"{r[k]['first']:.2f}" for k in KINDS)
        + f" | {r['NamedTuple']['first'] / r['RecordRef']['first']:.1f} | "
        + " | ".join(f"{1e6 * r[k]['call']:.1f}" for k in KINDS)
        + " | "
        + "; ".join(f"{r[k + ' cached']['first']:.2f}, {r[k + ' cached']['hits']}" for k in KINDS)
        + " |\n"
        for r in results
    )
    return (
        "# Passing records to compiled code: by value or by reference\n\n"
        f"`python {name}` (see its docstring): a chain of {DEPTH} compiled functions, none inlined, "
        "passing one record of arrays down; a new process with an empty numba cache per cell, one "
        "core of the shared 2-core machine.\n\n" + head + body + "\n"
        "Compile: the first call's wall time, numba's import excluded. Call: the whole chain "
        f"({2**DEPTH - 1} calls) from Python, mean of {CALLS}. Second process: the first call's "
        "wall time and the entry point's cache hits in a new process on the same cache (NamedTuple; "
        "StructRef; RecordRef): all load their machine code.\n"
    )


def main() -> None:
    argparse.ArgumentParser(description=__doc__.split("\n\n")[0]).parse_args()
    text = page(rows())
    write_text(RESULTS / "record_passing.md", text)
    sys.stdout.write(text)


if __name__ == "__main__":
    main()
