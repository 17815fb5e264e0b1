"""The one driver: Simulation advances in pieces, actuates between them and reports its run."""

from dataclasses import replace

import numpy as np
import pytest

from ballenv.physics import Ground, Ring, Scene, Simulation, simulate
from ballenv.physics.base.layout import ENERGY_BUDGET, ENERGY_TOTAL
from ballenv.physics.build import initial_state
from tests.stability.invariants import audit


def _scene(**kw):
    settings = dict(grounds=[Ground(friction=0.5)], adaptive=True, dt=1e-2) | kw
    return Scene(rings=[Ring(n_nodes=16, pressure=20e3)], **settings)


def test_one_advance_is_simulate():
    scene = _scene()
    sim = Simulation(scene, expected_end=0.3)
    assert sim.advance(0.3)
    traj, ref = sim.trajectory(), simulate(scene, 0.3)
    np.testing.assert_array_equal(traj.x, ref.x)
    assert traj.stats.newton_iterations == ref.stats.newton_iterations


def test_advance_in_pieces_lands_on_each_time_and_keeps_counting():
    sim = Simulation(_scene(), output_dt=0.01)
    assert sim.advance(0.125)
    assert sim.t == 0.125
    steps = sim.stats().steps
    assert sim.advance(0.6)
    traj = sim.trajectory()
    assert sim.t == 0.6 and traj.t[-1] == 0.6
    assert np.all(np.diff(traj.t) > 0) and 0.125 in traj.t
    assert sim.stats().steps > steps
    assert [kind for _, _, kind in traj.events][:1] == ["touchdown"]


def test_gas_and_impulse_between_advances_credit_the_energy_budget_exactly():
    sim = Simulation(_scene(gravity=0.0, grounds=()))
    assert sim.advance(0.01)
    m = sim.model.node_mass[0]
    before = sim.state.energy[0].copy()
    momentum = m * sim.state.v[0].sum(axis=0)
    sim.apply_impulse(0, [0, 1, 2, 3], (0.02, -0.01))
    np.testing.assert_allclose(m * sim.state.v[0].sum(axis=0) - momentum, [0.02, -0.01], rtol=1e-12)
    sim.set_rest_pressure(0, 35e3)
    after = sim.state.energy[0]
    gained = after[ENERGY_TOTAL] - before[ENERGY_TOTAL]
    assert gained != 0.0
    assert after[ENERGY_BUDGET] - before[ENERGY_BUDGET] == pytest.approx(gained, rel=1e-12)
    assert sim.advance(0.05)  # and the run goes on within its new budget


def test_gas_of_a_ring_without_gas_is_refused():
    sim = Simulation(Scene(rings=[Ring(n_nodes=8, pressure=None)]))
    with pytest.raises(ValueError, match="ring 0 holds no gas"):
        sim.set_rest_pressure(0, 1e4)


def test_a_failed_advance_says_why_and_keeps_the_last_accepted_state():
    scene = Scene(rings=[Ring(n_nodes=16)], grounds=[Ground()], adaptive=True, dt=1e-2, dt_min=1e-3,
                  impulse_tol=1e-6)  # fmt: skip
    sim = Simulation(scene)
    assert not sim.advance(1.0)
    assert "impulse_tol" in sim.failure
    assert np.all(np.isfinite(sim.state.x)) and sim.t < 1.0


def test_advance_refuses_a_time_in_the_past_or_not_a_number():
    sim = Simulation(_scene())
    assert sim.advance(0.01)
    for bad in (0.005, float("nan"), "1"):
        with pytest.raises(ValueError, match="Simulation.advance.t"):
            sim.advance(bad)


@pytest.mark.parametrize(
    ("call", "field"),
    [
        (lambda sim: sim.apply_impulse(0, [0, 99], (0.0, 1.0)), "nodes"),
        (lambda sim: sim.apply_impulse(0, [1, 1], (0.0, 1.0)), "nodes"),
        (lambda sim: sim.apply_impulse(0, [0.5], (0.0, 1.0)), "nodes"),
        (lambda sim: sim.apply_impulse(0, [0], (0.0, float("nan"))), "impulse"),
        (lambda sim: sim.apply_impulse(1, [0], (0.0, 1.0)), "ring"),
        (lambda sim: sim.set_rest_pressure(-1, 1e4), "ring"),
        (lambda sim: sim.set_rest_pressure(0, float("nan")), "pressure"),
        (lambda sim: sim.set_rest_pressure(0, 1e9), "pressure"),
    ],
)
def test_actuation_refuses_values_out_of_range_naming_them(call, field):
    sim = Simulation(_scene())
    with pytest.raises(ValueError, match=rf"Simulation\.(apply_impulse|set_rest_pressure)\.{field}"):
        call(sim)


def test_invalid_settings_name_the_driver():
    with pytest.raises(ValueError, match=r"Simulation\.output_dt"):
        Simulation(_scene(), output_dt=-1.0)
    with pytest.raises(ValueError, match=r"Simulation\.x0"):
        Simulation(_scene(), x0=np.zeros((3, 2)))


def _coincident(x):
    x[0, 5] = x[0, 4]
    return x


def _swapped(x):
    x[0, [3, 4]] = x[0, [4, 3]]  # edges 2-4 and 3-5 cross
    return x


@pytest.mark.parametrize(
    "start, message",
    [
        (np.zeros_like, r"simulate\.x0: nodes 0 and 1 of ring 0 are 0 m apart: neighbouring nodes must be"),
        (
            _coincident,
            r"simulate\.x0: nodes 4 and 5 of ring 0 are 0 m apart: .* more than 3\.9e-08 m apart",
        ),
        (lambda x: x[:, ::-1], r"simulate\.x0: the nodes of ring 0 run clockwise .* counter-clockwise"),
        (_swapped, r"simulate\.x0: the wall of ring 0 crosses itself: it must be a simple polygon"),
    ],
)
def test_a_start_shape_the_wall_cannot_take_is_refused_before_any_step(start, message):
    # these died in the compiled code (ZeroDivisionError) or as "Newton did not converge, lower dt"
    scene = _scene()
    x, _ = initial_state(scene)
    with pytest.raises(ValueError, match=message):
        simulate(scene, 0.01, x0=start(x.copy()))


def test_a_self_crossing_start_is_accepted_when_the_scene_ignores_self_crossing():
    scene = _scene(self_intersection="ignore")
    x, _ = initial_state(scene)
    sim = Simulation(scene, x0=_swapped(x.copy()))
    assert np.array_equal(sim.state.x, _swapped(x.copy()))


def _newton_failing_scene(**kw):
    """An empty ring (N = 32, h/R = 0.034) thrown at 32 m/s and 43 rad/s onto a 68 degree slope
    with friction 1.65: at about 0.021 s a step's Newton iteration fails at every step size down to
    dt_min (soak scene 178)."""
    ring = Ring(radius=0.18881142991470629, n_nodes=32, youngs_modulus=1074216.9474993646,
                thickness=0.006350014369236829, width=0.014167908243568662, density=1961.4932119773432,
                pressure=None, position=(0.20108013542952446, 0.0821051182907699),
                velocity=(-11.361737778033302, -29.413998681264477),
                angular_velocity=-42.561042459135464)  # fmt: skip
    return Scene(rings=[ring], grounds=[Ground(angle=-1.1831378464829028, friction=1.6540706110762229)],
                 contact="predictor_corrector", gravity=14.320238957165675, damping=50.0,
                 rho_infinity=0.26725345238367526, dt=0.0015329989521498202, adaptive=True,
                 impulse_tol=5e-3, atmospheric_pressure=0.0, gas_exponent=1.0, **kw)  # fmt: skip


def test_newton_rescue_carries_a_run_past_a_step_whose_newton_iteration_fails():
    t_end = 0.14970106297119393
    stopped = audit(_newton_failing_scene(newton_rescue_max_iter=0), t_end)
    assert not stopped.reached_end and "Newton's iteration did not converge" in stopped.error
    rescued = audit(_newton_failing_scene(), t_end)
    assert rescued.reached_end and rescued.problems() == []
    assert rescued.traj.stats.newton_rescues >= 1
    # the same run up to the stop: the rescue changes nothing before it
    k = len(stopped.traj.t)
    np.testing.assert_array_equal(rescued.traj.x[:k], stopped.traj.x)


def test_a_run_that_never_stops_is_the_same_with_or_without_newton_rescue():
    """At most three Newton corrections: many steps fail and are retried smaller, none down to
    dt_min, so the rescue never acts: the two runs agree to the last bit."""
    ring = Ring(radius=0.1, n_nodes=32, pressure=30e3, position=(0.0, 0.0))
    v0 = 8.0 * np.random.default_rng(4).standard_normal((1, 32, 2))
    settings = dict(gravity=0.0, integrator="backward_euler", dt=2e-3, adaptive=True, newton_max_iter=3)
    runs = [
        simulate(Scene(rings=[ring], newton_rescue_max_iter=rescue, **settings), 0.02, v0=v0)
        for rescue in (0, 200)
    ]
    assert runs[0].stats.rejections["newton"] > 0 and runs[1].stats.newton_rescues == 0
    np.testing.assert_array_equal(runs[0].x, runs[1].x)
    np.testing.assert_array_equal(runs[0].v, runs[1].v)
    assert runs[0].stats.newton_iterations == runs[1].stats.newton_iterations


def test_a_failed_newton_rescue_says_so():
    scene = replace(_newton_failing_scene(), newton_max_iter=1, newton_rescue_max_iter=2, dt_min=1e-4)
    sim = Simulation(scene)
    assert not sim.advance(0.11)
    assert "Newton's rescue failed too" in sim.failure
    assert sim.stats().newton_rescues == 0 and np.all(np.isfinite(sim.state.x))
