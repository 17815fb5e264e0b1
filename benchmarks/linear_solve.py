"""Options for the Newton linear solve of one ring, measured: the zig-zag band LU (kept) against a
dense LU (LAPACK through NumPy's np.linalg.solve, called from Python: about 2 us of the figure is
call overhead) of the same 2N x 2N matrix.

    python benchmarks/linear_solve.py     # writes benchmarks/results/linear_solve.md

Matrix: the Newton matrix of an inflated, damped, deformed ring (rank-4 Woodbury part included in
both). Median over 2000 solves, numba warm, OPENBLAS_NUM_THREADS=1.
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import pathlib  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402
from numba import njit  # noqa: E402

from ballenv.files import write_text  # noqa: E402
from ballenv.physics import Ring, Scene  # noqa: E402
from ballenv.physics.base.linalg import band_to_dense, solve_band_low_rank  # noqa: E402
from ballenv.physics.build import build_model, build_workspace  # noqa: E402
from ballenv.physics.effects.assembly import ring_jacobian  # noqa: E402

RESULTS = pathlib.Path(__file__).parent / "results"


@njit(cache=True)
def _band_loop(band0, ws, rank, rhs0, repeats):
    for _ in range(repeats):
        ws.band[:] = band0
        ws.res[:] = rhs0
        solve_band_low_rank(ws.band, ws.pos, ws.u, ws.w, rank, ws.res, ws.work, ws.cap, ws.coef)


def _dense_loop(dense, rhs0, repeats):
    out = rhs0
    for _ in range(repeats):
        out = np.linalg.solve(dense, rhs0)
    return out


def measure(n_nodes, repeats=2000):
    scene = Scene(rings=[Ring(n_nodes=n_nodes)], damping=5.0)
    model = build_model(scene)
    ws = build_workspace(n_nodes)
    rng = np.random.default_rng(0)
    theta = 2 * np.pi * np.arange(n_nodes) / n_nodes
    x = (
        0.1
        * np.stack([np.cos(theta), np.sin(theta)], axis=1)
        * (1 + 0.01 * rng.standard_normal((n_nodes, 1)))
    )
    v = rng.standard_normal(x.shape)
    rank = ring_jacobian(model, 0, x, v, 1e8, 1.0, 1e4, ws)
    band0 = ws.band.copy()
    dense = band_to_dense(band0, ws.pos) + ws.u[:, :rank] @ ws.w[:, :rank].T
    rhs = rng.standard_normal(2 * n_nodes)
    _band_loop(band0, ws, rank, rhs, 2)
    _dense_loop(dense, rhs, 2)
    t0 = time.perf_counter()
    _band_loop(band0, ws, rank, rhs, repeats)
    t_band = (time.perf_counter() - t0) / repeats * 1e6
    dense_repeats = max(10, repeats // (1 + n_nodes // 64))
    t0 = time.perf_counter()
    exact = _dense_loop(dense, rhs, dense_repeats)
    t_dense = (time.perf_counter() - t0) / dense_repeats * 1e6
    err = float(np.max(np.abs(ws.res - exact)) / np.max(np.abs(exact)))
    return t_band, t_dense, err


def main():
    RESULTS.mkdir(exist_ok=True)
    lines = [
        "| N | zig-zag band LU + Woodbury (us) | dense LU (us) | relative difference |",
        "|---:|---:|---:|---:|",
    ]
    for n in (16, 32, 64, 128, 256, 512):
        tb, td, err = measure(n)
        lines.append(f"| {n} | {tb:.1f} | {td:.1f} | {err:.1e} |")
    table = "\n".join(lines)
    write_text(RESULTS / "linear_solve.md", table + "\n")
    print(table)


if __name__ == "__main__":
    main()
