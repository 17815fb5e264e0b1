"""Where the first run's compile time goes, kernel by kernel: numba's compiler passes timed through
its event API (``numba:run_pass``) in a process on an empty cache (``NUMBA_CACHE_DIR``), for the
env's first steps (make, reset and three steps of ``InflatedBall-v3``), for the 3-D paddle env's
(``InflatedBall3DPaddle-v0``) and for the first ``simulate()`` of one ring on a floor (``Scene``'s
defaults, 20 ms).

Each scenario runs twice in the same minute: as the package compiles (module optimisation and
machine code only for the entry points Python calls, each with its whole call tree linked in,
``ballenv/physics/base/machine_code.py``) and with numba's own code library put back (every compiled
function's module optimised and emitted on its own, as numba does by default), so the page shows
what the lazy library saves as a ratio on the same machine. The libraries turned into machine code
are counted; the LLVM time is the module optimisation of the libraries optimised plus that machine
code.

A pass's time is its own (s): a callee compiled while its caller is typed is counted to the
callee. Per function: typing (numba's type inference passes), lowering (``native_lowering``: the
LLVM IR, its per-function optimisation and, where the library's module is optimised, that
optimisation, which includes every callee inlined into it) and the rest of numba's passes. The
table lists the functions that take the most, and the sums over all of them.

    python benchmarks/compile_profile.py   # writes benchmarks/results/compile_profile.md
"""

import argparse
import json
import os
import pathlib
import subprocess
import sys
import tempfile
import time

from ballenv.files import write_text

RESULTS = pathlib.Path(__file__).parent / "results"
TOP = 15  # functions listed per scenario

LISTENER = """
import json, sys, time
from numba.core import event

stack, rows = [], {}


class Passes(event.Listener):
    def on_start(self, ev):
        stack.append([ev.data["qualname"], ev.data["name"].split(" [")[0], time.perf_counter(), 0.0])

    def on_end(self, ev):
        name, step, start, nested = stack.pop()
        spent = time.perf_counter() - start
        row = rows.setdefault(name, {})
        row[step] = row.get(step, 0.0) + spent - nested
        if stack:
            stack[-1][3] += spent


event.register("numba:run_pass", Passes())

import ballenv.physics.base.jit  # noqa: E402,F401  (installs the lazy code library)
from numba.core import codegen  # noqa: E402

backend = {"libraries": 0, "seconds": 0.0}


def timed(method):
    def run(self, *args):
        start = time.perf_counter()
        try:
            return method(self, *args)
        finally:
            backend["seconds"] += time.perf_counter() - start
            backend["libraries"] += method.__name__ == "_finalize_specific"
    return run


if EAGER:  # numba's own library: every function's module optimised and emitted at once
    codegen.JITCPUCodegen._library_class = codegen.JITCodeLibrary
    codegen.JITCPUCodegen.set_env = ballenv.physics.base.machine_code._numba_set_env
codegen.CPUCodeLibrary._optimize_final_module = timed(codegen.CPUCodeLibrary._optimize_final_module)
codegen.JITCodeLibrary._finalize_specific = timed(codegen.JITCodeLibrary._finalize_specific)
"""

SCENARIOS = {
    "env": """
import gymnasium as gym
import ballenv  # noqa: F401
env = gym.make("InflatedBall-v3")
env.reset(seed=0)
for _ in range(3):
    env.step(env.action_space.sample())
""",
    "env3d": """
import gymnasium as gym
import ballenv  # noqa: F401
env = gym.make("InflatedBall3DPaddle-v0")
env.reset(seed=0)
for _ in range(3):
    env.step(env.action_space.sample())
""",
    "simulate": """
from ballenv.physics import Ground, Ring, Scene, simulate
simulate(Scene(rings=[Ring(radius=0.1, n_nodes=32, pressure=30e3, position=(0.0, 0.3))],
               grounds=[Ground()]), t_end=0.02)
""",
}
LIBRARIES = {"lazy (the package)": False, "eager (numba's own)": True}
TYPING = ("nopython_type_inference", "partial_type_inference", "nopython_rewrites")
LOWERING = ("native_lowering",)


def profile(scenario, eager):
    """(wall s, {function: {pass: own s}}, {"libraries": emitted, "seconds": LLVM module
    optimisation and machine code}) of ``scenario`` on an empty cache; with ``eager``, numba's own
    code library."""
    with tempfile.TemporaryDirectory() as cache:
        out = pathlib.Path(cache) / "passes.json"
        dump = f"\njson.dump([rows, backend], open({str(out)!r}, 'w'))\n"
        env = dict(os.environ, NUMBA_CACHE_DIR=str(pathlib.Path(cache) / "numba"))
        start = time.perf_counter()
        code = f"EAGER = {eager}\n" + LISTENER + SCENARIOS[scenario] + dump
        subprocess.run([sys.executable, "-c", code], env=env, check=True, capture_output=True)
        rows, backend = json.loads(out.read_text())
        return time.perf_counter() - start, rows, backend


def split(passes):
    """(typing, lowering, rest) s of one function's passes."""
    typing = sum(t for p, t in passes.items() if p in TYPING)
    lowering = sum(t for p, t in passes.items() if p in LOWERING)
    return typing, lowering, sum(passes.values()) - typing - lowering


def summary(scenario, runs):
    """A results table of ``scenario``: lazy and eager machine code side by side."""
    lines = [
        f"## {scenario}",
        "",
        "| code library | wall (s) | numba's passes (s) | typing (s) | lowering (s) | libraries emitted "
        "| module optimisation and machine code (s) |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    for label, (wall, rows, backend) in runs.items():
        total = [sum(split(p)[k] for p in rows.values()) for k in range(3)]
        lines.append(
            f"| {label} | {wall:.1f} | {sum(total):.1f} | {total[0]:.1f} | {total[1]:.1f} "
            f"| {backend['libraries']} | {backend['seconds']:.1f} |"
        )
    walls = [run[0] for run in runs.values()]
    lines += ["", f"Wall time, lazy over eager: {walls[0] / walls[1]:.2f}.", ""]
    return "\n".join(lines)


def table(scenario, wall, rows):
    """The functions of one scenario's run that take the most."""
    parts = {name: split(passes) for name, passes in rows.items()}
    lines = [
        f"Functions of the lazy run that take the most ({len(rows)} compiled):",
        "",
        "| function | typing (s) | lowering (s) | other (s) | total (s) |",
        "|---|---:|---:|---:|---:|",
    ]
    ranked = sorted(parts.items(), key=lambda item: -sum(item[1]))
    for name, (typing, lowering, rest) in ranked[:TOP]:
        total = typing + lowering + rest
        lines.append(f"| `{name}` | {typing:.2f} | {lowering:.2f} | {rest:.2f} | {total:.2f} |")
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=pathlib.Path, default=RESULTS / "compile_profile.md")
    parser.add_argument("--scenario", choices=sorted(SCENARIOS), nargs="*", default=sorted(SCENARIOS))
    args = parser.parse_args()
    sections = []
    loads = [os.getloadavg()[0]]
    for scenario in args.scenario:
        runs = {label: profile(scenario, eager) for label, eager in LIBRARIES.items()}
        loads.append(os.getloadavg()[0])
        lazy = runs[next(iter(LIBRARIES))]
        sections.append(summary(scenario, runs) + "\n" + table(scenario, lazy[0], lazy[1]))
        print(sections[-1], flush=True)
    page = (
        "# Compile profile: where the first run's compile time goes\n\n"
        f"`python benchmarks/compile_profile.py` on {os.cpu_count()} cores (1-minute load average "
        f"{min(loads):.1f}-{max(loads):.1f}: above {os.cpu_count()}, other processes shared the cores), "
        "an empty `NUMBA_CACHE_DIR` per scenario. Own time of numba's passes per function "
        "(a callee compiled while its caller is typed counts to the callee); lowering includes LLVM's "
        "per-function optimisation and, for a library whose module is optimised (in the lazy run an "
        "entry point's only), that module optimisation and machine code, with everything linked into it. "
        "The machine's speed varies from day to "
        "day: compare the shares, not the seconds of different days.\n\n" + "\n\n".join(sections) + "\n"
    )
    write_text(args.out, page)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
