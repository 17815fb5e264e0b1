"""Shared fixtures: a local Ray cluster for the tests of the sweeps and searches that run on one; and
the groups pytest-xdist's workers take the tests in (``make test``: ``--dist loadgroup``)."""

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


SHELL = ("tests", "shell")


def pytest_collection_modifyitems(config, items):
    """Each test file is one xdist group, run by one worker (its module fixtures are built once),
    and the 3-D ball's files (tests/shell) are one group together: one worker compiles the shell's
    kernels, where two workers starting on its files at once would both compile them."""
    for item in items:
        path = pathlib.Path(str(item.path)).resolve().relative_to(ROOT)
        group = "/".join(SHELL) if path.parts[:2] == SHELL else path.as_posix()
        item.add_marker(pytest.mark.xdist_group(group))
