"""What the first run costs on an empty numba cache: the wall and CPU time (s) of a process that makes
``InflatedBall-v3`` envs, resets them and takes three steps, with one env in the process and with
``--envs`` envs in as many subprocesses (gymnasium's ``AsyncVectorEnv``, spawned), and of a process
whose first ``simulate()`` runs ``Scene``'s defaults (the self-contact barrier, error control) with
one ring and with two (the joint step of rings in contact) on a floor for 20 ms, each run against a
new cache directory (``NUMBA_CACHE_DIR``; the checkout's own cache is not touched), then once more
on the cache it filled (a cached start: Python's imports, loading the kernels, the run itself), and
the env's cached start split into its phases.

    python benchmarks/cold_start.py   # writes benchmarks/results/cold_start.md (about 8 min)

The subprocesses compile each kernel once between them (``ballenv/physics/base/compile_lock.py``): the
first to need it compiles it, the others wait and load it from the cache, so four envs take about
the CPU time of one.
"""

import argparse
import json
import os
import pathlib
import resource
import subprocess
import sys
import tempfile
import time

from ballenv.files import write_text

RESULTS = pathlib.Path(__file__).parent / "results"

FIRST_STEPS = """
import sys
import gymnasium as gym
import ballenv  # noqa: F401  (registers the env)

if __name__ == "__main__":
    n = int(sys.argv[1])
    if n == 1:
        envs = gym.make("InflatedBall-v3")
    else:
        envs = gym.make_vec("InflatedBall-v3", num_envs=n, vectorization_mode="async",
                            vector_kwargs={"context": "spawn"})
    envs.reset(seed=0)
    for _ in range(3):
        envs.step(envs.action_space.sample())
    envs.close()
"""

FIRST_SIMULATE = """
import sys
from ballenv.physics import Ground, Ring, Scene, simulate
from ballenv.files import write_text  # noqa: E402

n = int(sys.argv[1])
rings = [Ring(radius=0.1, n_nodes=32, pressure=30e3, position=(0.25 * k, 0.3)) for k in range(n)]
simulate(Scene(rings=rings, grounds=[Ground()]), t_end=0.02)
"""

CACHED_PHASES = """
import json, time
start = time.perf_counter()
import gymnasium as gym
import ballenv  # noqa: F401
import numba.core.registry
imported = time.perf_counter()
numba.core.registry.cpu_target.target_context.refresh()
refreshed = time.perf_counter()
env = gym.make("InflatedBall-v3")
env.reset(seed=0)
made = time.perf_counter()
for _ in range(3):
    env.step(env.action_space.sample())
stepped = time.perf_counter()
print(json.dumps([imported - start, refreshed - imported, made - refreshed, stepped - made]))
"""
PHASES = (
    "imports (numpy, gymnasium, ballenv, numba)",
    "numba's registries of its implementations (once per process, before its first cached kernel "
    "loads; includes its BLAS check, which imports scipy.linalg when SciPy is installed)",
    "make and reset: loading the kernels from the cache, the ball's set-up",
    "three steps",
)


def cold_start(script, n, phases=False):
    """(wall s, CPU s of the process and its subprocesses) of ``script`` run with the argument ``n``
    (envs or rings) on an empty numba cache, then (wall s, CPU s) of the same run again on the cache
    that the first one filled (a cached start); with ``phases``, also the seconds of each of
    ``PHASES`` in a cached env start (best of 5)."""
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache, OPENBLAS_NUM_THREADS="1")
        runs = _timed(script, n, env), _timed(script, n, env)
        if not phases:
            return runs
        split = [json.loads(_output(CACHED_PHASES, env)) for _ in range(5)]
        return (*runs, [min(column) for column in zip(*split, strict=True)])


def _output(script, env):
    """What one subprocess running ``script`` in ``env`` prints."""
    done = subprocess.run([sys.executable, "-c", script], env=env, check=True, capture_output=True, text=True)
    return done.stdout


def _timed(script, n, env):
    """(wall s, CPU s) of one subprocess running ``script`` with argument ``n`` in ``env``."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run([sys.executable, "-c", script, str(n)], env=env, check=True, capture_output=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--envs", type=int, default=4, help="subprocess envs of the vector run (default 4)")
    args = parser.parse_args()
    *single, split = cold_start(FIRST_STEPS, 1, phases=True)
    envs = [(1, *single), (args.envs, *cold_start(FIRST_STEPS, args.envs))]
    scenes = [(n, *cold_start(FIRST_SIMULATE, n)) for n in (1, 2)]
    columns = "| wall (s) | CPU (s) | cached: wall (s) | cached: CPU (s) |"
    lines = [
        "# Cold start: the first steps on an empty numba cache",
        "",
        f"`python benchmarks/cold_start.py` on {os.cpu_count()} cores, a new `NUMBA_CACHE_DIR` per run. "
        "The env: make, reset and three steps of `InflatedBall-v3`.",
        "",
        "| envs " + columns,
        "|---:|---:|---:|---:|---:|",
        *(
            f"| {n} ({'one process' if n == 1 else 'AsyncVectorEnv'}) "
            f"| {w:.1f} | {c:.1f} | {cw:.2f} | {cc:.2f} |"
            for n, (w, c), (cw, cc) in envs
        ),
        "",
        "The simulator: the first `simulate()` of `Scene`'s defaults (the self-contact barrier, error "
        "control), rings of 32 nodes on a floor, 20 ms.",
        "",
        "| rings " + columns,
        "|---:|---:|---:|---:|---:|",
        *(f"| {n} | {w:.1f} | {c:.1f} | {cw:.2f} | {cc:.2f} |" for n, (w, c), (cw, cc) in scenes),
        "",
        "The env's cached start (one process), phase by phase, best of 5 runs on the filled cache:",
        "",
        "| phase | wall (s) |",
        "|---|---:|",
        *(f"| {name} | {seconds:.2f} |" for name, seconds in zip(PHASES, split, strict=True)),
        f"| sum of the phases' best | {sum(split):.2f} |",
        "",
    ]
    text = "\n".join(lines)
    print(text)
    write_text(RESULTS / "cold_start.md", text)


if __name__ == "__main__":
    main()
