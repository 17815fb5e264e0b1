"""Compile the simulator ahead of the first run: ``ballenv-compile`` (= ``python -m ballenv.compile``)
fills numba's on-disk cache for the env and the common scenes, so that the first ``gym.make``,
``reset`` and ``step`` or ``simulate()`` after an install loads compiled code instead of waiting for
numba.

Each job below runs in its own process (spawned), as many at once as there are cores (``--jobs``),
the longest first; a line per finished job says what it compiled and how long it took (s, wall).
Jobs that share kernels on an empty cache may compile some of them twice, one in each process; a job
that starts after another has written a kernel loads it. A second run finds everything cached and
takes about a second per job.

    ballenv-compile                 # every job
    ballenv-compile --only env      # the jobs whose names start with "env"
"""

import argparse
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from multiprocessing import get_context


def _env(action_mode):
    """Make, reset and step ``InflatedBall-v3`` in ``action_mode`` (its compiled reset and step)."""
    import gymnasium as gym

    import ballenv  # noqa: F401  (registers the env)

    env = gym.make("InflatedBall-v3", action_mode=action_mode)
    env.reset(seed=0)
    for _ in range(3):
        env.step(env.action_space.sample())
    env.close()


def _rings_on_floor(n_rings):
    """The first ``simulate()`` of ``Scene``'s defaults: ``n_rings`` rings of 32 nodes on a floor."""
    from .physics import Ground, Ring, Scene, simulate

    rings = [Ring(radius=0.1, n_nodes=32, pressure=30e3, position=(0.25 * k, 0.3)) for k in range(n_rings)]
    simulate(Scene(rings=rings, grounds=[Ground()]), t_end=0.02)


# name -> (function, argument), longest first: the joint step of two rings compiles the most, then
# the env, then one ring (benchmarks/results/cold_start.md)
JOBS = {
    "simulate, two rings on a floor": (_rings_on_floor, 2),
    "env, pressure mode": (_env, "pressure"),
    "env, paddle mode": (_env, "paddle"),
    "simulate, one ring on a floor": (_rings_on_floor, 1),
}


def _run(name):
    """Run job ``name``; its wall time (s)."""
    function, argument = JOBS[name]
    start = time.perf_counter()
    function(argument)
    return time.perf_counter() - start


def compile_jobs(names, jobs):
    """Run the jobs ``names`` in up to ``jobs`` processes at once, printing a line per finished job;
    the total wall time (s)."""
    start = time.perf_counter()
    with ProcessPoolExecutor(max_workers=jobs, mp_context=get_context("spawn")) as pool:
        futures = {pool.submit(_run, name): name for name in names}
        for done, future in enumerate(as_completed(futures), 1):
            print(f"[{done}/{len(names)}] {futures[future]}: {future.result():.0f} s", flush=True)
    return time.perf_counter() - start


def main(argv=None):
    parser = argparse.ArgumentParser(prog="ballenv-compile", description=__doc__.split("\n\n")[0])
    parser.add_argument("--only", default="", help="run the jobs whose names start with this (default: all)")
    cores = os.cpu_count() or 1
    parser.add_argument("--jobs", type=int, default=cores, help="processes at once (default: cores)")
    args = parser.parse_args(argv)
    if args.jobs < 1:
        parser.error(f"--jobs must be at least 1, got {args.jobs}")
    names = [name for name in JOBS if name.startswith(args.only)]
    if not names:
        parser.error(f"--only {args.only!r} names no job; the jobs are: {', '.join(JOBS)}")
    jobs = min(args.jobs, len(names))
    print(f"compiling the simulator: {len(names)} job{'s' * (len(names) != 1)}, {jobs} at once", flush=True)
    total = compile_jobs(names, jobs)
    print(f"compiled in {total:.0f} s; later runs load it from the cache", flush=True)


if __name__ == "__main__":
    sys.exit(main())
