"""The O(N) band + low-rank solve equals a dense solve; the zig-zag order makes the cyclic band plain."""

import numpy as np
import pytest

from ballenv.physics.base.linalg import (
    BAND_COLUMNS,
    BAND_HALF_WIDTH,
    MAX_LOW_RANK,
    SOLVE_COLUMNS,
    band_add_block,
    band_to_dense,
    solve_band_low_rank,
    solve_band_low_rank_columns,
    solve_band_wide_low_rank,
    zigzag_positions,
)
from ballenv.physics.build import build_model, build_workspace
from ballenv.physics.effects.assembly import ring_jacobian
from ballenv.physics.scene import Ring, Scene

from ..conftest import deformed_ring


@pytest.mark.parametrize("n_nodes", [3, 4, 5, 8, 9, 64, 65])
def test_zigzag_keeps_ring_neighbours_within_the_band(n_nodes):
    pos = zigzag_positions(n_nodes)
    assert sorted(pos) == list(range(n_nodes))
    for i in range(n_nodes):
        for d in (1, 2):
            j = (i + d) % n_nodes
            assert abs(pos[i] - pos[j]) <= 4
    assert 2 * 4 + 1 == BAND_HALF_WIDTH


def _random_cyclic_system(n_nodes, rank, seed):
    rng = np.random.default_rng(seed)
    pos = zigzag_positions(n_nodes)
    band = np.zeros((2 * n_nodes, BAND_COLUMNS))
    for i in range(n_nodes):
        for d in (-2, -1, 0, 1, 2):
            j = (i + d) % n_nodes
            blk = rng.standard_normal(4)
            if d == 0:
                blk[0] += 20.0
                blk[3] += 20.0
            band_add_block(band, pos, i, j, *blk)
    u = np.zeros((2 * n_nodes, MAX_LOW_RANK))
    w = np.zeros((2 * n_nodes, MAX_LOW_RANK))
    u[:, :rank] = rng.standard_normal((2 * n_nodes, rank))
    w[:, :rank] = rng.standard_normal((2 * n_nodes, rank)) / n_nodes
    return pos, band, u, w


@pytest.mark.parametrize("n_nodes", [3, 7, 64, 257])
@pytest.mark.parametrize("rank", [0, 1, 4])
def test_band_low_rank_solve_equals_dense_solve(n_nodes, rank):
    pos, band, u, w = _random_cyclic_system(n_nodes, rank, seed=n_nodes + rank)
    dense = band_to_dense(band, pos) + u[:, :rank] @ w[:, :rank].T
    rhs = np.random.default_rng(1).standard_normal(2 * n_nodes)
    expected = np.linalg.solve(dense, rhs)
    x = rhs.copy()
    ok = solve_band_low_rank(
        band, pos, u, w, rank, x, np.zeros((2 * n_nodes, 1 + MAX_LOW_RANK)),
        np.zeros((MAX_LOW_RANK, MAX_LOW_RANK)), np.zeros(MAX_LOW_RANK),
    )  # fmt: skip
    assert ok
    assert np.max(np.abs(x - expected)) <= 1e-10 * np.max(np.abs(expected))


@pytest.mark.parametrize("integrator_coefficients", [(1e6, 1.0, 1e3), (2e8, 0.5, 3e4)])
def test_newton_matrix_of_a_full_scene_solves_like_dense(integrator_coefficients):
    """The assembled Newton matrix (pressure + rigid-motion damping) solved in O(N) == dense solve."""
    n = 64
    scene = Scene(rings=[Ring(n_nodes=n)], damping=20.0)
    model = build_model(scene)
    ws = build_workspace(n)
    x = deformed_ring(n, radius=0.1, amplitude=0.1)
    v = np.random.default_rng(2).standard_normal(x.shape)
    c_mass, c_x, c_v = integrator_coefficients
    rank = ring_jacobian(model, 0, x, v, c_mass, c_x, c_v, ws)
    assert rank == 4
    dense = band_to_dense(ws.band, ws.pos) + ws.u[:, :rank] @ ws.w[:, :rank].T
    rhs = np.random.default_rng(3).standard_normal(2 * n)
    expected = np.linalg.solve(dense, rhs)
    sol = rhs.copy()
    assert solve_band_low_rank(ws.band, ws.pos, ws.u, ws.w, rank, sol, ws.work, ws.cap, ws.coef)
    assert np.max(np.abs(sol - expected)) <= 1e-10 * np.max(np.abs(expected))


def test_zero_pivot_is_reported_not_divided_by():
    n = 4
    pos = zigzag_positions(n)
    band = np.zeros((2 * n, BAND_COLUMNS))
    x = np.ones(2 * n)
    u = np.zeros((2 * n, MAX_LOW_RANK))
    assert not solve_band_low_rank(
        band, pos, u, u, 0, x, np.zeros((2 * n, 1 + MAX_LOW_RANK)),
        np.zeros((MAX_LOW_RANK, MAX_LOW_RANK)), np.zeros(MAX_LOW_RANK),
    )  # fmt: skip


def _wide_factors(n_nodes, dense_rank, sparse_rank, seed):
    """Low-rank factors ``u, w`` (2N, rank) of the self-contact barrier's kind: ``dense_rank``
    dense columns (the effects'), then ``sparse_rank`` columns of a unit ``u`` and a ``w`` with six
    nonzeros (a coupled node's row)."""
    rng = np.random.default_rng(seed)
    rank = dense_rank + sparse_rank
    u = np.zeros((2 * n_nodes, rank))
    w = np.zeros((2 * n_nodes, rank))
    u[:, :dense_rank] = rng.standard_normal((2 * n_nodes, dense_rank))
    w[:, :dense_rank] = rng.standard_normal((2 * n_nodes, dense_rank)) / n_nodes
    for c in range(dense_rank, rank):
        u[rng.integers(2 * n_nodes), c] = 1.0
        w[rng.choice(2 * n_nodes, 6, replace=False), c] = rng.standard_normal(6)
    return u, w


@pytest.mark.parametrize("n_nodes", [8, 64, 257])
@pytest.mark.parametrize("ranks", [(0, 0), (3, 0), (0, 12), (4, 30)])
def test_wide_and_many_column_solves_equal_dense_solves(n_nodes, ranks):
    pos, band, _, _ = _random_cyclic_system(n_nodes, 0, seed=n_nodes)
    u, w = _wide_factors(n_nodes, *ranks, seed=n_nodes + sum(ranks))
    rank, n2 = u.shape[1], 2 * n_nodes
    dense = band_to_dense(band, pos) + u @ w.T
    cols = np.random.default_rng(3).standard_normal((n2, 7))
    expected = np.linalg.solve(dense, cols)
    room = max(rank, 1)
    x = cols[:, 0].copy()
    assert solve_band_wide_low_rank(
        band.copy(), pos, u, w, rank, x, np.zeros((n2, SOLVE_COLUMNS)), np.zeros((n2, rank + 1)),
        np.zeros((room, room)), np.zeros(room),
    )  # fmt: skip
    assert np.max(np.abs(x - expected[:, 0])) <= 1e-10 * np.max(np.abs(expected[:, 0]))
    many = cols.copy()
    assert solve_band_low_rank_columns(
        band.copy(), pos, u, w, rank, many, 7, np.zeros((n2, SOLVE_COLUMNS)), np.zeros((n2, room)),
        np.zeros((room, room)), np.zeros(room, dtype=np.int64), np.zeros(room),
    )  # fmt: skip
    assert np.max(np.abs(many - expected)) <= 1e-10 * np.max(np.abs(expected))
