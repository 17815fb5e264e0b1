"""Independent simulations run in this process or as Ray tasks on a local or remote cluster.

The sweeps (``benchmarks/soak.py``, ``benchmarks/work_precision.py``, ``python -m ballenv.scenes``)
and the training searches (``agents.study``, ``agents.tune``) hand their independent runs to
:func:`run_tasks`, which calls ``fn(item)`` for every item and yields ``(index, result)`` pairs as
they finish, with a progress bar:

* ``cluster=None``: one after the other in this process, in order (the serial run).
* ``cluster="local"``: a Ray cluster started on this machine for the sweep (``num_cpus`` workers,
  default: every core), stopped after it.
* ``cluster="auto"`` or an address (``"10.0.0.5:6379"``, ``"ray://head:10001"``): a running
  cluster (``ray start --head``), left running.

What a task returns does not depend on where it runs: the same items give the same results as the
serial run (a simulation is deterministic and each task gets its item whole). Ray retries a task
whose worker died (the process killed, the node lost) up to ``max_retries`` times; a task whose
every attempt died is yielded as :class:`TaskLost` and the sweep goes on, so the results of every
other task are kept; a task whose ``fn`` raised on the cluster is yielded as :class:`TaskFailed`
(with the exception's type and message) beside the others. Each index is yielded exactly once,
whether its task was retried or not. In the serial run an exception of ``fn`` is raised at once.

numba compiles the simulator's kernels on first use (a minute or more) and caches them on disk, in the
folder named by the package's sources (``ballenv.physics.base.cache_location``), which every
worker of a node shares.
``warm`` (a function of no arguments) runs first, once on each node, so that the node's workers load
the compiled kernels from its cache instead of each compiling them at the same time.

Ray is an optional dependency (``pip install 'ballenv[ray]'``); only a call with a ``cluster``
imports it.
"""

import dataclasses
import os
import time
from collections.abc import Callable, Iterator, Sequence
from typing import Any

from tqdm.auto import tqdm

from .extras import optional_module

LOCAL = "local"  # start a Ray cluster on this machine for the sweep
RETRIES = 3  # Ray's default for tasks: attempts after the first when a worker dies


@dataclasses.dataclass(frozen=True)
class TaskLost:
    """The outcome of a task whose every attempt died with its worker (``reason``: Ray's error)."""

    index: int
    reason: str


@dataclasses.dataclass(frozen=True)
class TaskFailed:
    """The outcome of a task whose ``fn`` raised on the cluster (``reason``: the exception)."""

    index: int
    reason: str


def check_cluster(cluster: str | None) -> str | None:
    """``cluster`` if it names a cluster (:func:`run_tasks`); a ValueError naming it otherwise."""
    if cluster is None or (isinstance(cluster, str) and cluster.strip()):
        return cluster
    raise ValueError(
        f"cluster = {cluster!r} is invalid: must be None (this process), 'local', 'auto' or a Ray "
        "address such as 'host:6379' or 'ray://host:10001'"
    )


def _ray():
    return optional_module("ray", "running a sweep on a Ray cluster", "ray", "ray")


def connect(
    cluster: str,
    num_cpus: int | None = None,
    paths: Sequence[str] = (),
    env_vars: dict[str, str] | None = None,
) -> bool:
    """Connect this process to ``cluster`` (start one for ``"local"``) unless Ray is already
    initialised; ``paths`` are added to the workers' ``PYTHONPATH`` (the folders the task functions
    are imported from, e.g. a checkout's root for ``benchmarks`` and ``tests``), ``env_vars`` set in
    their environment (e.g. ``NUMBA_CACHE_DIR``). Returns whether this call started the connection
    (the caller then shuts it down)."""
    ray = _ray()
    if ray.is_initialized():
        return False
    python_path = [str(p) for p in paths] + [
        p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p
    ]
    env_vars = {"OPENBLAS_NUM_THREADS": os.environ.get("OPENBLAS_NUM_THREADS", "1"), **(env_vars or {})}
    if python_path:
        env_vars["PYTHONPATH"] = os.pathsep.join(dict.fromkeys(python_path))
    local = cluster == LOCAL
    ray.init(
        address=None if local else cluster,
        num_cpus=num_cpus if local else None,
        include_dashboard=False,
        runtime_env={"env_vars": env_vars},
        logging_level="WARNING",
    )
    return True


def warm_nodes(warm: Callable[[], Any]) -> dict[str, float]:
    """Run ``warm`` once on each alive node with CPUs, all nodes at once; its time (s) by node id."""
    ray = _ray()
    from ray.util.scheduling_strategies import NodeAffinitySchedulingStrategy

    @ray.remote(num_cpus=1)
    def timed():
        start = time.perf_counter()
        warm()
        return time.perf_counter() - start

    nodes = [n["NodeID"] for n in ray.nodes() if n["Alive"] and n["Resources"].get("CPU", 0) >= 1]
    refs = [
        timed.options(scheduling_strategy=NodeAffinitySchedulingStrategy(n, soft=False)).remote()
        for n in nodes
    ]
    return dict(zip(nodes, ray.get(refs), strict=True))


def warm_simulator(run: Callable[..., Any] | None = None) -> None:
    """A ``warm`` for sweeps of simulations: ``run(scene, t_end)`` (default
    :func:`ballenv.physics.simulate`) on one and on two small rings with each integrator and contact
    method, fixed and adaptive steps, three steps each: it compiles (or loads from numba's cache) the
    kernels a sweep of scenes calls, their energies included."""
    from dataclasses import replace

    from ballenv.physics import Ground, Ring, Scene, simulate

    run = simulate if run is None else run
    ring = Ring(radius=0.1, n_nodes=8, youngs_modulus=1e7, thickness=0.005, width=0.02, pressure=1e4)
    pair = [replace(ring, position=(0.0, 0.2)), replace(ring, position=(0.5, 0.2))]
    for rings in (pair[:1], pair):
        for contact in ("mass_modification", "predictor_corrector"):
            for integrator in ("backward_euler", "generalized_alpha"):
                for adaptive in (False, True):
                    scene = Scene(rings=rings, grounds=[Ground()], contact=contact, integrator=integrator,
                                  adaptive=adaptive, dt=1e-3)  # fmt: skip
                    result = run(scene, 3e-3)
                    if hasattr(result, "energy"):
                        result.energy()


def _serial(fn, items, bar) -> Iterator[tuple[int, Any]]:
    for index, item in enumerate(items):
        result = fn(item)
        bar.update()
        yield index, result


def _on_ray(fn, items, bar, max_retries) -> Iterator[tuple[int, Any]]:
    ray = _ray()
    remote = ray.remote(num_cpus=1, max_retries=max_retries)(fn)
    index_of = {remote.remote(item): index for index, item in enumerate(items)}
    pending = list(index_of)
    while pending:
        (ref,), pending = ray.wait(pending, num_returns=1)
        index = index_of.pop(ref)
        try:
            result = ray.get(ref)
        except (
            ray.exceptions.WorkerCrashedError,
            ray.exceptions.OutOfMemoryError,
            ray.exceptions.NodeDiedError,
        ) as died:
            result = TaskLost(index, f"{type(died).__name__}: {str(died).splitlines()[0]}")
        except ray.exceptions.RayTaskError as raised:  # fn raised: kept beside the other results
            cause = raised.cause if raised.cause is not None else raised
            result = TaskFailed(index, f"{type(cause).__name__}: {str(cause).splitlines()[-1]}")
        bar.update()
        yield index, result


def run_tasks(
    fn: Callable[[Any], Any],
    items: Sequence[Any],
    cluster: str | None = None,
    *,
    desc: str = "tasks",
    num_cpus: int | None = None,
    max_retries: int = RETRIES,
    warm: Callable[[], Any] | None = None,
    paths: Sequence[str] = (),
    progress: bool = True,
) -> Iterator[tuple[int, Any]]:
    """``(index, fn(items[index]))`` for every item, as the tasks finish (in order when serial); a
    task lost with its worker after ``max_retries`` retries gives ``(index, TaskLost)``. ``cluster``,
    ``warm``, ``paths``: the module docstring and :func:`connect` (the warm-up's time is written
    above the progress bar). ``fn`` and the items must pickle (a module-level function) for a cluster."""
    check_cluster(cluster)
    if isinstance(max_retries, bool) or not isinstance(max_retries, int) or max_retries < 0:
        raise ValueError(f"run_tasks.max_retries = {max_retries!r} is invalid: must be an integer >= 0")
    with tqdm(total=len(items), desc=desc, unit="task", disable=not progress) as bar:
        if cluster is None:
            yield from _serial(fn, items, bar)
            return
        started = connect(cluster, num_cpus, paths)
        try:
            if warm is not None:
                seconds = warm_nodes(warm)
                if progress:
                    longest = max(seconds.values())
                    bar.write(f"numba's cache warmed on {len(seconds)} node(s) in {longest:.1f} s")
            yield from _on_ray(fn, items, bar, max_retries)
        finally:
            if started:
                _ray().shutdown()


def collect(outcomes: Iterator[tuple[int, Any]], count: int) -> tuple[list[Any], list[TaskLost | TaskFailed]]:
    """The results of :func:`run_tasks` in item order (``None`` where a task was lost or failed) and
    the lost and failed tasks; a ValueError if an index came twice or not at all."""
    results: list[Any] = [None] * count
    seen = [False] * count
    lost: list[TaskLost | TaskFailed] = []
    for index, result in outcomes:
        if seen[index]:
            raise ValueError(f"task {index} gave two results")
        seen[index] = True
        if isinstance(result, TaskLost | TaskFailed):
            lost.append(result)
        else:
            results[index] = result
    missing = [i for i, s in enumerate(seen) if not s]
    if missing:
        raise ValueError(f"tasks {missing[:10]} gave no result")
    return results, lost
