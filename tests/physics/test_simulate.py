"""The simulator against analytic results: free fall, breathing mode, hoop tension, gas law,
momentum and energy balances, convergence orders, step rejection."""

import math

import numpy as np
import pytest

from ballenv.physics import Ring, Scene, SimulationError, energy, simulate
from ballenv.physics.base.geometry import polygon_area
from ballenv.physics.base.ring import inflated_radius

E, RHO, R = 10e6, 1100.0, 0.1
BREATHING_OMEGA = math.sqrt(E / RHO) / R  # rad/s


def _ring(**kw):
    base = dict(radius=R, n_nodes=64, youngs_modulus=E, density=RHO, thickness=2e-3, width=0.02)
    base.update(kw)
    return Ring(**base)


def _free_fall_error(integrator, dt, t_end=0.1):
    scene = Scene(rings=[_ring(pressure=None)], integrator=integrator, dt=dt, gravity=9.81)
    traj = simulate(scene, t_end)
    y = traj.centre_of_mass()[:, 0, 1]
    return np.max(np.abs(y - (1.0 - 0.5 * 9.81 * traj.t**2)))


def test_free_fall_backward_euler_is_first_order():
    coarse = _free_fall_error("backward_euler", 1e-3)
    fine = _free_fall_error("backward_euler", 5e-4)
    assert coarse > 1e-5
    assert coarse / fine == pytest.approx(2.0, rel=0.05)


def test_free_fall_generalized_alpha_is_exact_for_constant_gravity():
    # second order (Newmark with a consistent start acceleration) integrates constant
    # acceleration exactly: the error is round-off, far below C dt^2
    for dt in (1e-3, 5e-4):
        assert _free_fall_error("generalized_alpha", dt) < 1e-12


def _breathing(integrator, dt, periods, eps0=1e-4, **scene_kw):
    ring = _ring(pressure=None, position=(0.0, 0.0))
    theta = 2 * np.pi * np.arange(64) / 64
    x0 = R * (1 + eps0) * np.stack([np.cos(theta), np.sin(theta)], axis=1)
    scene = Scene(rings=[ring], gravity=0.0, integrator=integrator, dt=dt, **scene_kw)
    traj = simulate(scene, periods * 2 * math.pi / BREATHING_OMEGA, x0=x0)
    radius = np.linalg.norm(traj.x[:, 0], axis=2).mean(axis=1)
    return traj, radius


def test_breathing_mode_frequency_is_sqrt_E_over_rho_over_R():
    traj, radius = _breathing("generalized_alpha", 5e-6, periods=5.2)
    s = radius - R
    idx = np.nonzero(np.sign(s[:-1]) != np.sign(s[1:]))[0]
    crossings = traj.t[idx] - s[idx] * (traj.t[idx + 1] - traj.t[idx]) / (s[idx + 1] - s[idx])
    period = 2 * np.mean(np.diff(crossings))
    assert len(crossings) >= 8
    assert 2 * math.pi / period == pytest.approx(BREATHING_OMEGA, rel=5e-3)


@pytest.mark.parametrize(("integrator", "order"), [("backward_euler", 1), ("generalized_alpha", 2)])
def test_breathing_mode_convergence_order(integrator, order):
    period = 2 * math.pi / BREATHING_OMEGA
    errors = []
    for steps in (80, 160):
        traj, radius = _breathing(integrator, period / steps, periods=1.0)
        exact = R * (1 + 1e-4 * np.cos(BREATHING_OMEGA * traj.t))
        errors.append(np.max(np.abs(radius - exact)))
    assert errors[0] / errors[1] == pytest.approx(2.0**order, rel=0.1)


def _circle(radius, n_nodes=64):
    theta = 2 * np.pi * np.arange(n_nodes) / n_nodes
    return radius * np.stack([np.cos(theta), np.sin(theta)], axis=1)


def _pressurised_equilibrium(pressure, n_nodes=64):
    """Release the ring unstretched (radius R) and let damping settle it on its inflated circle."""
    scene = Scene(
        rings=[_ring(pressure=pressure, n_nodes=n_nodes, position=(0.0, 0.0))],
        gravity=0.0,
        damping=200.0,
        integrator="backward_euler",
        dt=1e-3,
    )
    return scene, simulate(scene, 1.0, x0=_circle(R, n_nodes), output_dt=0.1)


@pytest.mark.parametrize("pressure", [1e3, 30e3])
def test_pressurised_ring_settles_where_hoop_tension_p_b_r_balances_the_gas(pressure):
    scene, traj = _pressurised_equilibrium(pressure)
    ring = scene.rings[0]
    x = traj.x[-1, 0]
    radius = np.linalg.norm(x - x.mean(axis=0), axis=1).mean()
    edges = np.linalg.norm(np.roll(x, -1, axis=0) - x, axis=1)
    strain = edges.mean() / (2 * R * math.sin(math.pi / 64)) - 1
    p = traj.pressure[-1, 0]
    ea = ring.youngs_modulus * ring.width * ring.thickness
    assert np.max(np.abs(traj.v[-1])) < 1e-6  # at rest
    # thin-ring hoop tension T = p b r (cos(pi/N): the polygon's edges meet at an angle)
    assert strain * ea == pytest.approx(p * ring.width * radius * math.cos(math.pi / 64), rel=1e-6)
    # the inflated start is that same equilibrium, and Ring.pressure is its gauge pressure
    assert p == pytest.approx(pressure, rel=1e-6)
    assert radius == pytest.approx(inflated_radius(ring), rel=1e-7)


def test_a_pressurised_ring_starts_inflated_and_at_rest():
    ring = _ring(pressure=30e3, position=(0.0, 0.0))
    traj = simulate(Scene(rings=[ring], gravity=0.0, dt=1e-4), 0.01)
    assert inflated_radius(ring) > 1.05 * R  # 30 kPa stretches this wall by about 7 %
    assert np.max(np.abs(traj.v)) < 1e-8
    np.testing.assert_allclose(traj.pressure[:, 0], 30e3, rtol=1e-9)


def test_gas_law_holds_along_a_trajectory():
    ring = _ring(pressure=30e3, position=(0.0, 0.0), velocity=(0.0, 0.0))
    rng = np.random.default_rng(0)
    theta = 2 * np.pi * np.arange(64) / 64
    x0 = R * np.stack([0.8 * np.cos(theta), 1.1 * np.sin(theta)], axis=1)
    scene = Scene(rings=[ring], gravity=0.0, dt=1e-5)
    traj = simulate(scene, 0.01, x0=x0, v0=rng.standard_normal((64, 2)))
    p_atm = scene.atmospheric_pressure
    area = np.array([polygon_area(x) for x in traj.x[:, 0]])
    invariant = (traj.pressure[:, 0] + p_atm) * area
    a_inflated = 64 * inflated_radius(ring) ** 2 * math.sin(2 * math.pi / 64) / 2
    assert np.max(np.abs(invariant / ((30e3 + p_atm) * a_inflated) - 1)) < 1e-9
    assert np.ptp(area) / area.mean() > 0.01  # the gas really was squashed and expanded


@pytest.mark.parametrize("integrator", ["backward_euler", "generalized_alpha"])
def test_linear_momentum_is_conserved_without_external_force(integrator):
    rng = np.random.default_rng(1)
    ring = _ring(pressure=30e3, position=(0.0, 0.0), velocity=(2.0, -1.0), angular_velocity=5.0)
    scene = Scene(rings=[ring], gravity=0.0, damping=30.0, integrator=integrator, dt=1e-4)
    theta = 2 * np.pi * np.arange(64) / 64
    x0 = R * np.stack([np.cos(theta), 0.9 * np.sin(theta)], axis=1)
    v0 = np.array([2.0, -1.0]) + 0.5 * rng.standard_normal((64, 2))
    traj = simulate(scene, 0.05, x0=x0, v0=v0)
    momentum = traj.v[:, 0].sum(axis=1)  # equal node masses
    assert np.max(np.abs(momentum - momentum[0])) < 1e-10 * np.linalg.norm(momentum[0])


def _vibration_energy_kept(integrator, dt):
    scene_eq, traj_eq = _pressurised_equilibrium(30e3, n_nodes=32)
    x_eq = traj_eq.x[-1, 0] - traj_eq.x[-1, 0].mean(axis=0)
    theta = np.arctan2(x_eq[:, 1], x_eq[:, 0])
    radial = x_eq / np.linalg.norm(x_eq, axis=1)[:, None]
    x0 = x_eq + 1e-3 * (1.0 + np.cos(2 * theta))[:, None] * radial
    ring = scene_eq.rings[0]
    scene = Scene(rings=[ring], gravity=0.0, integrator=integrator, dt=dt)
    e_eq = energy(scene, x_eq[None], np.zeros_like(x_eq)[None])["total"]
    period = 2 * math.pi / BREATHING_OMEGA
    traj = simulate(scene, 100 * period, x0=x0, output_dt=period)
    e = traj.energy()["total"][:, 0]
    return (e[-1] - e_eq) / (e[0] - e_eq)


def test_second_order_scheme_keeps_vibration_energy_where_backward_euler_loses_it():
    dt = 2e-5
    kept_ga = _vibration_energy_kept("generalized_alpha", dt)
    kept_be = _vibration_energy_kept("backward_euler", dt)
    assert 0.99 <= kept_ga <= 1.01
    assert kept_be < 0.9


def test_failed_newton_steps_are_rejected_and_retried_smaller():
    rng = np.random.default_rng(4)
    ring = _ring(pressure=30e3, n_nodes=32, position=(0.0, 0.0))
    theta = 2 * np.pi * np.arange(32) / 32
    x0 = R * np.stack([np.cos(theta), np.sin(theta)], axis=1)
    v0 = 5.0 * rng.standard_normal((32, 2))
    for adaptive in (True, False):
        scene = Scene(rings=[ring], gravity=0.0, dt=2e-3, adaptive=adaptive, newton_max_iter=3)
        traj = simulate(scene, 0.02, x0=x0, v0=v0)
        assert traj.stats.rejected_steps > 0
        assert traj.t[-1] == pytest.approx(0.02)
        assert np.all(np.isfinite(traj.x))


def test_step_below_dt_min_raises_a_clear_error():
    rng = np.random.default_rng(4)
    ring = _ring(pressure=30e3, n_nodes=32, position=(0.0, 0.0))
    v0 = 5.0 * rng.standard_normal((32, 2))
    scene = Scene(
        rings=[ring], gravity=0.0, dt=2e-3, dt_min=1e-3, newton_max_iter=1, newton_rescue_max_iter=0
    )
    with pytest.raises(SimulationError, match="dt_min") as err:
        simulate(scene, 0.02, v0=v0)
    assert np.all(np.isfinite(err.value.trajectory.x))


def test_output_dt_records_exact_times_and_stats():
    scene = Scene(rings=[_ring()], dt=1e-4)
    traj = simulate(scene, 0.01, output_dt=1e-3)
    np.testing.assert_allclose(traj.t, np.arange(11) * 1e-3, atol=1e-15)
    assert traj.x.shape == (11, 1, 64, 2)
    assert traj.stats.steps == 100
    assert traj.stats.rejected_steps == 0
    assert traj.stats.newton_iterations >= traj.stats.steps
    assert traj.stats.effects == ("stretching", "bending", "pressure", "gravity")


@pytest.mark.parametrize(
    ("name", "change", "message"),
    [
        ("v0", lambda x, v: (x, v + 1e20), r"simulate.v0 has an entry of 1e\+20 m/s: each must be in"),
        ("x0", lambda x, v: (x + 1e12, v), r"simulate.x0 has an entry of 1e\+12 m: each must be in"),
        ("x0", lambda x, v: (x * 1e200, v), r"simulate.x0 has an entry of .* m: each must be in"),
    ],
)
def test_a_start_state_past_its_bounds_is_a_clear_error(name, change, message):
    from ballenv.physics.build import initial_state

    scene = Scene(rings=[Ring(n_nodes=16)])
    x, v = change(*initial_state(scene))
    with pytest.raises(ValueError, match=message):
        simulate(scene, 0.01, x0=x, v0=v)


@pytest.mark.parametrize(("field", "value"), [("radius", 1e-9), ("density", 1e-300)])
def test_rings_too_small_or_too_light_to_step_are_refused_by_name(field, value):
    with pytest.raises(ValueError, match=f"Ring.{field} = {value:g} is out of range"):
        Ring(**{field: value, "thickness": 1e-10} if field == "radius" else {field: value})
