"""agents.evaluate's interval of the mean apex error: Student's t for few episodes."""

import math

import numpy as np
import pytest
from scipy import stats

from agents.evaluate import evaluate, t_probability, t_quantile


@pytest.mark.parametrize("df", [1, 2, 3, 4, 5, 9, 10, 19, 29, 30, 99, 500, 5000])
def test_t_quantiles_are_scipys(df):
    assert t_quantile(0.975, df) == pytest.approx(stats.t.ppf(0.975, df), rel=1e-9)
    assert t_quantile(0.9, df) == pytest.approx(stats.t.ppf(0.9, df), rel=1e-9)
    for t in (0.1, 1.0, 2.5, 10.0):
        assert t_probability(t, df) == pytest.approx(2 * stats.t.cdf(t, df) - 1, abs=1e-12)


def test_known_values_and_the_range():
    assert t_quantile(0.975, 1) == pytest.approx(12.70620474, rel=1e-9)  # tables: 12.706
    assert t_quantile(0.975, 9) == pytest.approx(2.262157163, rel=1e-9)  # 2.262
    assert t_quantile(0.975, 10**6) == pytest.approx(1.959964, rel=1e-6)  # the normal's
    for p, df in ((0.5, 3), (1.0, 3), (0.975, 0)):
        with pytest.raises(ValueError, match="out of range"):
            t_quantile(p, df)


def test_the_scores_interval_is_students_t_of_the_episodes():
    score = evaluate("heuristic", {"action_mode": "pressure", "max_episode_steps": 150}, episodes=3)
    errors = np.array(score.episode_apex_errors)
    assert errors.std() > 0
    half = stats.t.ppf(0.975, 2) * errors.std(ddof=1) / math.sqrt(3)  # 4.30, not 1.96
    assert score.apex_error_ci95 == pytest.approx(half, rel=1e-9)
