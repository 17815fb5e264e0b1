"""Shared helpers for the physics tests: deformed rings, dense Jacobians, finite differences, runs in
two checkouts of the package."""

import os
import shutil
import subprocess
import sys

import numpy as np
import pytest

from ballenv.physics.base.linalg import BAND_COLUMNS, MAX_LOW_RANK, band_to_dense, zigzag_positions


def deformed_ring(n_nodes, radius=0.1, amplitude=0.02, seed=0):
    """Counter-clockwise ring of ``n_nodes`` with random radial and tangential perturbations (m)."""
    rng = np.random.default_rng(seed)
    theta = 2 * np.pi * np.arange(n_nodes) / n_nodes
    x = radius * np.stack([np.cos(theta), np.sin(theta)], axis=1)
    edge = 2 * radius * np.sin(np.pi / n_nodes)
    return x + amplitude * edge * rng.standard_normal(x.shape) + np.array([0.3, 0.7])


class DenseAssembler:
    """Runs a Jacobian kernel into band + low-rank storage and returns the dense 2N x 2N matrix."""

    def __init__(self, n_nodes):
        self.pos = zigzag_positions(n_nodes)
        self.band = np.zeros((2 * n_nodes, BAND_COLUMNS))
        self.u = np.zeros((2 * n_nodes, MAX_LOW_RANK))
        self.w = np.zeros((2 * n_nodes, MAX_LOW_RANK))

    def dense(self, rank=0):
        d = band_to_dense(self.band, self.pos)
        return d + self.u[:, :rank] @ self.w[:, :rank].T


def finite_difference_jacobian(force, x, step):
    """Central differences d force(x).ravel() / d x.ravel() (columns = perturbed DOFs)."""
    flat = x.ravel()
    out = np.empty((flat.size, flat.size))
    for k in range(flat.size):
        xp = flat.copy()
        xm = flat.copy()
        xp[k] += step
        xm[k] -= step
        out[:, k] = (force(xp.reshape(x.shape)).ravel() - force(xm.reshape(x.shape)).ravel()) / (2 * step)
    return out


def finite_difference_gradient(energy, x, step):
    """Central differences of a scalar energy(x) -> array of x's shape."""
    flat = x.ravel()
    out = np.empty(flat.size)
    for k in range(flat.size):
        xp = flat.copy()
        xm = flat.copy()
        xp[k] += step
        xm[k] -= step
        out[k] = (energy(xp.reshape(x.shape)) - energy(xm.reshape(x.shape))) / (2 * step)
    return out.reshape(x.shape)


def run_in_two_checkouts(tmp_path, script, package, **env):
    """``python -c script`` in two copies of ``package`` (the ``ballenv`` folder) in different folders
    under ``tmp_path``, one after the other, with ``env`` added to this process's environment; the
    two finished processes."""
    runs = []
    for name in ("first", "second"):
        copy = tmp_path / name / "ballenv"
        shutil.copytree(package, copy, ignore=shutil.ignore_patterns("__pycache__"))
        run_env = dict(os.environ, PYTHONPATH=str(copy.parent), **env)
        run = [sys.executable, "-c", script]
        runs.append(
            subprocess.run(run, env=run_env, capture_output=True, text=True, timeout=300, cwd=tmp_path)
        )
    return runs


def relative_error(a, b):
    """max |a - b| / max |b|."""
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


@pytest.fixture
def assembler_factory():
    return DenseAssembler
