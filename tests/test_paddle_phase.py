"""benchmarks/paddle_phase.py: the scripted paddle's strikes with their landing rotation phase, and
the out-of-sample least squares that reports what the phase explains."""

import numpy as np

from .benchmark_modules import load_benchmark


def test_the_fits_find_a_known_dependence_on_the_phase_and_nothing_in_noise():
    paddle_phase = load_benchmark("paddle_phase")
    rng = np.random.default_rng(0)
    q = rng.uniform(0.0, 1.0, 2000)
    noise = rng.normal(0.0, 0.01, 2000)
    error = 0.02 * np.cos(2.0 * np.pi * q + 0.3) - 0.01 * np.sin(6.0 * np.pi * q) + noise
    left = paddle_phase.linear_residual_sd(error, paddle_phase.phase_harmonics(q))
    assert abs(left - 0.01) < 0.0006  # the noise only
    unrelated = rng.normal(size=(2000, 3))
    assert paddle_phase.linear_residual_sd(error, unrelated) > 0.99 * error.std()


def test_each_strike_has_its_phases_and_the_error_of_the_bounce_it_set():
    paddle_phase = load_benchmark("paddle_phase")
    data = paddle_phase.strikes(episodes=2)
    assert set(data) == set(paddle_phase.COLUMNS) and len({len(v) for v in data.values()}) == 1
    assert len(data["error"]) >= 20
    for name in ("phase after", "phase before", "phase now"):
        assert np.all((0.0 <= data[name]) & (data[name] < 1.0)) and np.ptp(data[name]) > 0.5
    assert np.all(data["impulse"] > 0.0)  # every row a strike (its impulse, N s)
    assert np.abs(data["error"]).mean() < 0.05  # the scripted paddle's bounces land near the target
