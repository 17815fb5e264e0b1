"""The grounds' motion: the plane's offset and its surface's velocity against their closed forms
(the velocity is the offset's derivative), the belt's slide, and the step limit that keeps a
plane moving toward a shell from passing half the way to its nearest vertex."""

import math

import numpy as np
import pytest

from ballenv.shell import Ground
from ballenv.shell.touch.motion import PERIOD_STEPS, STEP_FRACTION, Motion

TILTED = (0.0, 0.6, 0.8)


def motion_of(*grounds, dhat=1e-3):
    return Motion(grounds, np.zeros(len(grounds)), np.zeros((len(grounds), 3)), dhat)


def test_a_moving_plane_is_where_its_closed_form_puts_it_and_moves_at_its_derivative():
    g = Ground(normal=TILTED, height=0.2, velocity=(1.0, -0.5, 0.25), amplitude=0.01, frequency=3.0)
    m = motion_of(g)
    n, u = np.array(TILTED), np.array(g.velocity)
    omega = 2 * math.pi * 3.0
    for t in (0.0, 0.07, 0.4):
        assert m.offsets(t)[0] == pytest.approx(0.2 + (n @ u) * t + 0.01 * math.sin(omega * t), abs=1e-15)
        w = u + 0.01 * omega * math.cos(omega * t) * n
        assert np.allclose(m.surface_velocities(t)[0], w, atol=1e-14)
        eps = 1e-6
        rate = (m.offsets(t + eps)[0] - m.offsets(t - eps)[0]) / (2 * eps)
        assert rate == pytest.approx(n @ w, rel=1e-7)


def test_a_step_writes_the_planes_at_its_end_and_the_belts_slide_along_the_plane():
    belt = Ground(normal=TILTED, velocity=(2.0, 1.0, 0.0))
    fixed = Ground(height=-1.0)
    m = motion_of(belt, fixed)
    x = np.array([[0.0, 0.0, 5.0]])
    h = m.prepare(x, 0.3, 0.01)
    assert h == 0.01  # the belt moves away from the vertex along its normal: no limit
    assert m.heights[0] == pytest.approx(0.6 * 1.0 * 0.31) and m.heights[1] == -1.0
    n = np.array(TILTED)
    assert np.allclose(m.slide[0], 0.01 * (np.array([2.0, 1.0, 0.0]) - 0.6 * n))
    assert m.slide[0] @ n == pytest.approx(0.0, abs=1e-16) and np.all(m.slide[1] == 0.0)


def test_a_plane_moving_toward_a_shell_advances_at_most_a_fraction_of_the_gap_per_step():
    plate = Ground(velocity=(0.0, 0.0, 2.0), amplitude=1e-3, frequency=50.0)
    m = motion_of(plate)
    x = np.array([[0.0, 0.0, 0.004], [1.0, 0.0, 0.3]])  # the nearest vertex 4 mm above, at t = 0
    h = m.prepare(x, 0.0, 1.0)
    rate = 2.0 + 1e-3 * 2 * math.pi * 50.0  # the fastest approach, m/s
    assert h == pytest.approx(min(STEP_FRACTION * 0.004 / rate, 1.0 / (PERIOD_STEPS * 50.0)))
    assert m.heights[0] == pytest.approx(m.offsets(h)[0])
    assert 0.004 - m.heights[0] >= (1 - STEP_FRACTION) * 0.004
    sinking = motion_of(Ground(velocity=(0.0, 0.0, -2.0)))
    assert sinking.prepare(x, 0.0, 1.0) == 1.0
