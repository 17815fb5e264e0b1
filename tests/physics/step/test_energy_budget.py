"""The momentum-keeping removal of kinetic energy behind the stepper's energy budget."""

import numpy as np
import pytest

from ballenv.physics.step.energy_budget import remove_internal_kinetic_energy


def _kinetic(v, m):
    return 0.5 * m * np.sum(v * v)


def test_removal_takes_exactly_the_excess_and_keeps_the_momentum():
    rng = np.random.default_rng(3)
    v = rng.normal(size=(16, 2)) + np.array([2.0, -1.0])
    m = 0.01
    before = v.copy()
    excess = 0.1 * (_kinetic(v, m) - _kinetic(v.mean(axis=0) * np.ones_like(v), m))
    assert remove_internal_kinetic_energy(np.zeros_like(v), v, m, excess)
    assert _kinetic(before, m) - _kinetic(v, m) == pytest.approx(excess, rel=1e-12)
    np.testing.assert_allclose(v.sum(axis=0), before.sum(axis=0), rtol=1e-13)
    # every node's velocity relative to the mean is scaled by the same factor
    ratio = (v - v.mean(axis=0)) / (before - before.mean(axis=0))
    np.testing.assert_allclose(ratio, ratio[0, 0], rtol=1e-12)


def test_removal_refuses_more_than_the_internal_kinetic_energy():
    v = np.tile([3.0, 0.0], (8, 1))  # pure translation: no internal kinetic energy
    assert not remove_internal_kinetic_energy(np.zeros_like(v), v, 0.01, 1e-9)
    np.testing.assert_array_equal(v, np.tile([3.0, 0.0], (8, 1)))
