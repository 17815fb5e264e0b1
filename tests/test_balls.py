"""The regulation balls: each passes its rule's drop test with its own settings, has the rule's size,
mass and pressure, and rebounds higher when pumped harder."""

import math

import pytest

from ballenv.balls import BALLS, PSI, drop, regulation_ring
from ballenv.physics.base.ring import inflated_radius, total_mass

KGF_PER_CM2 = 98066.5  # Pa

# the rules' ranges: circumference (m), mass (kg), gauge pressure (Pa) or None where left open
RULES = {
    "basketball": ((0.749, 0.780), (0.567, 0.650), (7.5 * PSI, 8.5 * PSI)),  # FIBA; the NBA's pressure
    "tennis_ball": ((math.pi * 0.0654, math.pi * 0.0686), (0.0560, 0.0594), None),  # ITF type 2
    "football": ((0.685, 0.695), (0.420, 0.445), (0.6 * 101325, 1.1 * 101325)),  # FIFA Quality Pro; Law 2
    "volleyball": ((0.65, 0.67), (0.260, 0.280), (0.300 * KGF_PER_CM2, 0.325 * KGF_PER_CM2)),  # FIVB
}


@pytest.mark.parametrize("name", [name for name in BALLS if BALLS[name]().drop_test is not None])
def test_each_ball_passes_its_rules_drop_test(name):
    ball = BALLS[name]()
    low, high = ball.drop_test.rebound
    result = drop(ball)
    assert low <= result.rebound <= high
    assert result.contact_time > 0.0 and result.peak_force > ball.mass * 9.81


@pytest.mark.parametrize("name", sorted(RULES))
def test_each_ball_has_its_rules_size_mass_and_pressure(name):
    ball = BALLS[name]()
    circumference, mass, pressure = RULES[name]
    assert circumference[0] <= 2.0 * math.pi * ball.radius <= circumference[1]
    assert mass[0] <= ball.mass <= mass[1]
    if pressure is not None:
        assert pressure[0] <= ball.ring.pressure <= pressure[1]


def test_regulation_ring_has_the_radius_and_mass_it_is_asked_for():
    ring = regulation_ring(0.11, 0.43, 8e4, 2e7, 3e-3, 0.22, n_nodes=48)
    assert inflated_radius(ring) == pytest.approx(0.11, rel=1e-12)
    assert total_mass(ring) == pytest.approx(0.43, rel=1e-12)


def test_basketball_rebounds_higher_when_pumped_harder_and_its_top_is_a_diameter_above_its_bottom():
    ball = BALLS["basketball"]()
    p = ball.ring.pressure
    low, rule, high = (drop(ball, pressure=f * p) for f in (0.8, 1.0, 1.2))
    assert low.rebound < rule.rebound < high.rebound
    bottom = rule.restitution**2 * rule.drop_height  # the rebound of the ball's bottom
    assert rule.rebound - bottom == pytest.approx(2.0 * ball.radius, rel=1e-9)  # FIBA measures the top
    no_test = drop(BALLS["volleyball"](), drop_height=1.8)
    assert no_test.drop_height == 1.8 and no_test.rebound < 1.8
