"""Shared fixtures: a local Ray cluster for the tests of the sweeps and searches that run on one."""

import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module")
def local_ray():
    """A Ray cluster on this machine with 2 CPUs for the tests of one module, its workers importing
    this checkout and its benchmark scripts; ``run_tasks(..., cluster="local")`` then uses it (and
    leaves it running)."""
    ray = pytest.importorskip("ray")
    from ballenv.cluster import connect

    connect("local", num_cpus=2, paths=[str(ROOT), str(ROOT / "benchmarks")])
    yield ray
    ray.shutdown()
