"""benchmarks/accuracy_spread.py: its trajectory error measures the centre of mass's path between
the steps exactly in flight, and is zero for a run against itself."""

import numpy as np
import pytest

from ballenv.physics import Ring, Scene, simulate

from .benchmark_modules import load_benchmark

spread = load_benchmark("accuracy_spread")
family = load_benchmark("ball_family")


def test_the_centre_path_is_the_flight_parabola_between_long_steps():
    """A ring falling freely in 10-ms steps: the spline through its records is ``y0 - g t^2 / 2`` at
    times between them (m, to round-off)."""
    scene = Scene(rings=[Ring(position=(0.0, 5.0))], grounds=[], adaptive=False, dt=1e-2)
    traj = simulate(scene, t_end=0.3)
    t = np.linspace(0.0, 0.3, 97)
    path = spread.centre_path(traj)(t)
    np.testing.assert_allclose(path[:, 1], 5.0 - 0.5 * 9.81 * t**2, rtol=0, atol=1e-12)
    np.testing.assert_allclose(path[:, 0], 0.0, atol=1e-12)


def test_a_drop_against_itself_has_no_apex_or_trajectory_error(monkeypatch):
    """The light ball at N = 16 as its own reference: both errors are zero at every height."""
    scene = family.ball_scene("light", 16, adaptive=True, dt=1e-2, rtol=3e-2)
    monkeypatch.setattr(spread, "reference_scene", lambda name, n_nodes: scene)
    references, paths = spread.reference_drops("light")
    assert references.shape == (len(spread.HEIGHT_FACTORS),)
    assert np.ptp(references) > 0.0  # the heights differ, and so do the apexes
    apex, path = spread.drop_errors("light", scene, references, paths)
    assert apex == pytest.approx(0.0, abs=1e-15) and path == pytest.approx(0.0, abs=1e-12)
