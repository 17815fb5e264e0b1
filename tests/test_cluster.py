"""ballenv.cluster: independent runs here or as Ray tasks on a local cluster, the same results either
way, a worker killed mid-sweep retried without counting its task twice."""

import os
import pathlib
import signal
import threading
import time

import numpy as np
import pytest

from ballenv.cluster import TaskFailed, TaskLost, check_cluster, collect, run_tasks
from ballenv.scenes import run as run_scene
from tests.benchmark_modules import BENCHMARKS, load_benchmark

ROOT = BENCHMARKS.parent
ray = pytest.importorskip("ray", reason="the ray extra (pip install 'ballenv[ray]') is not installed")


def square(x):
    return x * x


def test_serial_runs_give_every_result_in_order_and_collect_checks_each_index_once():
    outcomes = list(run_tasks(square, [3, 1, 2], progress=False))
    assert outcomes == [(0, 9), (1, 1), (2, 4)]
    assert collect(iter(outcomes), 3) == ([9, 1, 4], [])
    with pytest.raises(ValueError, match="task 1 gave two results"):
        collect(iter([(0, 9), (1, 1), (1, 1)]), 2)
    with pytest.raises(ValueError, match=r"tasks \[2\] gave no result"):
        collect(iter([(0, 9), (1, 1)]), 3)
    results, lost = collect(iter([(0, 9), (1, TaskLost(1, "WorkerCrashedError"))]), 2)
    assert results == [9, None] and lost == [TaskLost(1, "WorkerCrashedError")]


def test_bad_settings_are_named():
    with pytest.raises(ValueError, match=r"cluster = '' is invalid: must be None .*'local', 'auto'"):
        check_cluster("")
    with pytest.raises(ValueError, match=r"run_tasks.max_retries = -1 is invalid: must be an integer >= 0"):
        next(run_tasks(square, [1], max_retries=-1))


@pytest.fixture(scope="module")
def cluster(local_ray):
    """The name ``run_tasks`` takes for the module's local Ray cluster (``conftest.local_ray``)."""
    return "local"


@pytest.mark.slow  # 30 s of soak scenes; the scene grid on Ray below tests the same path to the bit
def test_the_soak_on_ray_tallies_as_the_serial_run(cluster):
    soak = load_benchmark("soak")
    serial, serial_lost, _ = soak.soak_scenes(12, seed=0)
    on_ray, ray_lost, _ = soak.soak_scenes(12, seed=0, cluster=cluster)
    assert ray_lost == [] and serial_lost == []
    tally, ends = on_ray.tally, on_ray.ends
    assert tally["cases"] == 12 and ends["reached t_end"] == 12
    assert not any(how.startswith(("undocumented", "crash")) for how in ends)
    assert on_ray[:3] == serial[:3]
    assert [s[:4] for s in on_ray.stops] == [s[:4] for s in serial.stops]  # scene by scene


def test_a_scene_grid_on_ray_is_the_serial_grid_to_the_bit(cluster):
    serial = run_scene("vibrating-plate", reduced=True)
    on_ray = run_scene("vibrating-plate", reduced=True, cluster=cluster)
    assert on_ray.metrics == serial.metrics
    assert serial.trajectories.keys() == on_ray.trajectories.keys()
    for label, traj in serial.trajectories.items():
        assert np.array_equal(traj.x, on_ray.trajectories[label].x), label


def stalled_square(task):
    """``x * x``; the task ``x == stall`` first writes its worker's pid and waits to be killed, and
    every attempt leaves a file, so that the test sees how often it ran."""
    x, stall, folder = task
    folder = pathlib.Path(folder)
    attempt = len(list(folder.glob(f"attempt-{x}-*")))
    (folder / f"attempt-{x}-{attempt}").touch()
    if x == stall and attempt == 0:
        (folder / "pid").write_text(str(os.getpid()))
        time.sleep(120)
    return x * x


def _kill_when_stalled(folder):
    pid = folder / "pid"
    deadline = time.monotonic() + 60
    while not pid.exists() or not pid.read_text():
        if time.monotonic() > deadline:
            return
        time.sleep(0.05)
    os.kill(int(pid.read_text()), signal.SIGKILL)


@pytest.mark.parametrize("retries", [1, 0])
def test_a_worker_killed_mid_sweep_is_retried_and_counted_once(cluster, tmp_path, retries):
    tasks = [(x, 3, str(tmp_path)) for x in range(8)]
    killer = threading.Thread(target=_kill_when_stalled, args=(tmp_path,))
    killer.start()
    outcomes = list(run_tasks(stalled_square, tasks, cluster, max_retries=retries, progress=False))
    killer.join()
    assert sorted(index for index, _ in outcomes) == list(range(8))  # each task once
    results, lost = collect(iter(outcomes), 8)
    attempts = len(list(tmp_path.glob("attempt-3-*")))
    if retries:
        assert results == [x * x for x in range(8)] and lost == [] and attempts == 2
    else:  # not retried: the task is reported lost, every other result kept
        assert [t.index for t in lost] == [3] and "WorkerCrashedError" in lost[0].reason
        assert results == [x * x if x != 3 else None for x in range(8)] and attempts == 1


def test_nothing_but_a_sweep_on_a_cluster_imports_ray():
    import subprocess
    import sys

    code = (
        "import sys, ballenv, ballenv.cluster, ballenv.scenes, ballenv.physics\n"
        "from ballenv.cluster import collect, run_tasks\n"
        "assert collect(run_tasks(abs, [-2], progress=False), 1) == ([2], [])\n"
        "assert 'ray' not in sys.modules, 'ray imported'"
    )
    subprocess.run([sys.executable, "-c", code], check=True, cwd=ROOT)


def test_the_aws_cluster_configuration_passes_ray_s_schema():
    yaml = pytest.importorskip("yaml")
    from ray.autoscaler._private.util import prepare_config, validate_config

    config = yaml.safe_load((ROOT / "docs" / "ray-cluster-aws.yaml").read_text())
    validate_config(prepare_config(config))  # raises on a field Ray's cluster launcher does not know
    setup = " ".join(config["setup_commands"])
    assert "constraints.txt" in setup and "[ray" in setup  # the pinned install, the ray extra


def fails_on_two(x):
    if x == 2:
        raise ArithmeticError(f"no square of {x} today")
    return x * x


def test_a_task_that_raises_on_the_cluster_is_kept_beside_the_finished_ones(cluster):
    results, lost = collect(run_tasks(fails_on_two, [3, 2, 4], cluster, progress=False), 3)
    assert results == [9, None, 16]
    assert lost == [TaskFailed(1, "ArithmeticError: no square of 2 today")]
