"""The broad phases' sort and sweep (``ballenv.physics.walls.broad_phase``)."""

import numpy as np
import pytest

from ballenv.physics.base.jit import kernel
from ballenv.physics.walls.broad_phase import overlapping_pairs, sort_by


@kernel
def _sorted(order, key):
    sort_by(order, key)


@pytest.mark.parametrize("n", [1, 2, 17, 200])
def test_sort_by_orders_indices_by_their_keys_from_any_start(n):
    rng = np.random.default_rng(n)
    key = rng.normal(size=n)
    order = rng.permutation(n).astype(np.int64)
    _sorted(order, key)
    assert sorted(order) == list(range(n))
    assert np.all(np.diff(key[order]) >= 0)
    key += rng.normal(scale=1e-3, size=n)  # keys that moved a little: the kept order is nearly sorted
    _sorted(order, key)
    assert np.all(np.diff(key[order]) >= 0)


def test_broad_phase_finds_every_overlapping_pair():
    rng = np.random.default_rng(2)
    for _ in range(20):
        n = rng.integers(2, 40)
        lo = rng.uniform(0.0, 3.0, size=(n, 2))
        box = np.concatenate([lo, lo + rng.uniform(0.05, 0.4, size=(n, 2))], axis=1)
        margin = rng.uniform(0.0, 0.05, size=n)
        order = rng.permutation(n).astype(np.int64)
        pairs = np.zeros((n * (n - 1) // 2, 2), dtype=np.int64)
        count = overlapping_pairs(box, margin, order, np.zeros(n), pairs)
        grown = box + np.stack([-margin, -margin, margin, margin], axis=1)
        expected = {
            (a, b)
            for a in range(n)
            for b in range(a + 1, n)
            if grown[a, 0] <= grown[b, 2]
            and grown[b, 0] <= grown[a, 2]
            and grown[a, 1] <= grown[b, 3]
            and grown[b, 1] <= grown[a, 3]
        }
        assert {tuple(p) for p in pairs[:count]} == expected
