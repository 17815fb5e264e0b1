"""A sweep on a local Ray cluster: speed-up from one to two workers, the overhead per task, and a
start on an empty numba cache with and without the warm-up.

    python benchmarks/cluster_scaling.py [--scenes 200]   # writes benchmarks/results/cluster_scaling.md

The sweep is the soak's first ``--scenes`` random scenes (``benchmarks/soak.py``), run three ways
through ``ballenv.cluster.run_tasks``: in this process, and on a local Ray cluster of one and of two
workers (``num_cpus``), each started fresh (its start-up timed apart), with each node's numba cache
warmed first (``ballenv.cluster.warm_simulator``, timed apart; the cache on disk is warm). The
tallies of the three runs must be equal. The overhead per task: 400 tasks that return at once, on
each cluster (wall time x workers / 400). Last, the first ``--cold-scenes`` scenes on two
workers compiling into an empty numba cache, with the warm-up task and without it.
"""

import argparse
import pathlib
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import ray  # noqa: E402

from ballenv.cluster import collect, connect, run_tasks, warm_simulator  # noqa: E402
from ballenv.files import write_text  # noqa: E402
from tests.stability.invariants import audit  # noqa: E402

sys.path.insert(0, str(ROOT / "benchmarks"))
from soak import draw_scenes, run_scene, tally_scenes  # noqa: E402

RESULTS = ROOT / "benchmarks" / "results"


def nothing(x):
    return x


def one_way(tasks, workers):
    """Run the sweep in this process (``workers`` 0) or on a fresh local cluster of ``workers``:
    {outcomes, per-task times, sweep wall, start-up, warm-up, overhead per task}."""
    out = {"startup": 0.0, "warm": 0.0, "overhead": float("nan")}
    cluster = None
    if workers:
        start = time.perf_counter()
        connect("local", num_cpus=workers, paths=[str(ROOT), str(ROOT / "benchmarks")])
        out["startup"] = time.perf_counter() - start
        start = time.perf_counter()
        list(run_tasks(nothing, [0] * workers, "local", progress=False, warm=lambda: warm_simulator(audit)))
        out["warm"] = time.perf_counter() - start
        start = time.perf_counter()
        list(run_tasks(nothing, list(range(400)), "local", progress=False))
        out["overhead"] = (time.perf_counter() - start) * workers / 400
        cluster = "local"
    else:
        start = time.perf_counter()
        warm_simulator(audit)
        out["warm"] = time.perf_counter() - start
    start = time.perf_counter()
    results, lost = collect(run_tasks(run_scene, tasks, cluster, desc=f"{workers} workers"), len(tasks))
    out["sweep"] = time.perf_counter() - start
    if lost:
        raise SystemExit(f"scenes lost with their worker: {[t.index for t in lost]}")
    out["outcomes"] = results
    out["times"] = [r.seconds for r in results]
    if workers:
        ray.shutdown()
    return out


def cold_start(tasks, warm):
    """Wall time (s) of ``tasks`` on a fresh 2-worker local cluster whose workers compile into an
    empty numba cache, with the warm-up first (``warm``) or without (each worker compiles what its
    first scenes call, both at once), and the workers' CPU time (s) of the compiling."""
    with tempfile.TemporaryDirectory() as cache:
        connect(
            "local",
            num_cpus=2,
            paths=[str(ROOT), str(ROOT / "benchmarks")],
            env_vars={"NUMBA_CACHE_DIR": cache},
        )
        start = time.perf_counter()
        warming = (lambda: warm_simulator(audit)) if warm else None
        results, lost = collect(
            run_tasks(run_scene, tasks, "local", progress=False, warm=warming), len(tasks)
        )
        wall = time.perf_counter() - start
        ray.shutdown()
    return wall, sum(r.seconds for r in results if r is not None)


def report(args, runs, cold):
    serial, one, two = runs
    tallies = [tally_scenes(draw_scenes(args.scenes, 0), r["outcomes"])[:3] for r in runs]
    same = tallies[0] == tallies[1] == tallies[2]
    times = serial["times"]
    lines = [
        "# A sweep on a local Ray cluster",
        "",
        f"`python benchmarks/cluster_scaling.py --scenes {args.scenes}` (ray {ray.__version__}; this "
        "machine's 2 cores; numba's cache on disk warm). The sweep: the soak's first "
        f"{args.scenes} scenes; tallies of the three runs {'equal' if same else 'DIFFERENT'}.",
        "",
        "| run | sweep wall (s) | speed-up over one worker | cluster start (s) | warm-up (s) "
        "| overhead per task (ms) |",
        "|---|---:|---:|---:|---:|---:|",
        f"| in this process | {serial['sweep']:.1f} | - | - | {serial['warm']:.1f} | - |",
        f"| Ray, 1 worker | {one['sweep']:.1f} | 1.00 | {one['startup']:.1f} | {one['warm']:.1f} "
        f"| {1e3 * one['overhead']:.2f} |",
        f"| Ray, 2 workers | {two['sweep']:.1f} | {one['sweep'] / two['sweep']:.2f} | {two['startup']:.1f} "
        f"| {two['warm']:.1f} | {1e3 * two['overhead']:.2f} |",
        "",
        f"Per scene (in this process): mean {1e3 * sum(times) / len(times):.0f} ms, longest "
        f"{max(times):.1f} s (scene {times.index(max(times))}); the two workers' sweep cannot end "
        "before its longest scene.",
        "",
        "The full soak's scene times, and the least wall time they allow on 64 cores: "
        "[soak.md](soak.md) (`benchmarks/soak.py`).",
    ]
    lines += [
        "",
        f"On an empty numba cache (`NUMBA_CACHE_DIR` a new folder; the first {args.cold_scenes} scenes, "
        "2 workers, cluster start not counted):",
        "",
        "| | sweep wall (s) | the scenes' own time in the workers (s) |",
        "|---|---:|---:|",
        *[
            f"| {'warm-up once on the node first' if warm else 'no warm-up: each worker compiles'} "
            f"| {wall:.1f} | {work:.1f} |"
            for warm, (wall, work) in cold.items()
        ],
    ]
    return "\n".join(lines) + "\n"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", type=int, default=200)
    parser.add_argument("--cold-scenes", type=int, default=20, help="scenes of the empty-cache runs")
    args = parser.parse_args()
    tasks = draw_scenes(args.scenes, 0)
    runs = [one_way(tasks, workers) for workers in (0, 1, 2)]
    cold = {warm: cold_start(tasks[: args.cold_scenes], warm) for warm in (True, False)}
    text = report(args, runs, cold)
    print(text)
    write_text(RESULTS / "cluster_scaling.md", text)


if __name__ == "__main__":
    main()
