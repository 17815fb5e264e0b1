"""Stability suite: the named hard cases, each with both contact methods and both integrators.

For every run: every accepted state finite, no node below a ground by more than
``GROUND_TOLERANCE`` (1e-6 m) and none inside another ring, the total energy (kinetic + elastic +
gas + gravity) never above its start value by more than ``ENERGY_ROUND_OFF`` (1e-9) of the start's
sum of |energy parts|, and t_end reached. Newton failures end in rejected steps; a scene that cannot
go on stops at ``Scene.dt_min`` with a SimulationError that says why.
"""

import math
from dataclasses import replace

import numpy as np
import pytest

from ballenv.physics import Ground, Ring, Scene, SimulationError, simulate
from ballenv.physics.base.geometry import polygon_area
from ballenv.physics.base.layout import REJECT_NEWTON
from ballenv.physics.build import build_model, build_workspace, empty_state
from ballenv.physics.step.integrator import build_solver
from ballenv.physics.step.stepper import initial_state_values, try_step

from .cases import CONTACTS, INTEGRATORS, hard_cases, released_flat
from .invariants import audit

CASES = {case.name: case for case in hard_cases()}


@pytest.mark.parametrize("integrator", INTEGRATORS)
@pytest.mark.parametrize("contact", CONTACTS)
@pytest.mark.parametrize("name", list(CASES))
def test_hard_case_is_stable(name, contact, integrator):
    case = CASES[name].variant(contact, integrator)
    result = audit(case.scene, case.t_end, case.x0, case.v0)
    assert result.problems() == [], result
    assert result.reached_end, result.error
    assert result.steps > 0


def test_the_cases_are_as_hard_as_named():
    """The scenes reach the extremes their names claim."""
    flat = CASES["squashed_flat"]
    height = np.ptp(flat.x0[:, 1])
    assert height <= 0.1 * 2 * flat.scene.rings[0].radius + 1e-3  # walls 1 cm apart, 20 cm ball
    run = audit(flat.scene, flat.t_end, flat.x0, flat.v0)
    assert run.traj.pressure.min() > 1e6  # the gas is squeezed to over 10 bar and holds
    assert np.ptp(run.traj.x[-1, 0, :, 1]) < 0.03  # ... between the plates
    pairs = CASES["two_balls_20_m_s"].scene.rings
    assert pairs[0].velocity[0] - pairs[1].velocity[0] == 40.0  # each at 20 m/s
    two = audit(CASES["two_balls_20_m_s"].scene, 0.1)
    v = two.traj.v.mean(axis=2)[-1, :, 0]
    assert v[0] < 0.0 < v[1]  # they met and bounced apart without passing through
    assert CASES["slope_75_deg"].scene.grounds[0].angle == pytest.approx(math.radians(75))
    assert {c.scene.rings[0].n_nodes for c in CASES.values()} >= {8, 512}
    press = CASES["collapsed_by_external_pressure"]
    ring = press.scene.rings[0]
    run = audit(press.scene, press.t_end)
    np.testing.assert_allclose(run.traj.pressure, ring.pressure, rtol=1e-12)  # the regulator holds it
    x = run.traj.x[-1, 0]
    assert polygon_area(x) < 0.1 * math.pi * ring.radius**2  # pressed flat ...
    n = len(x)
    apart = np.abs(np.subtract.outer(np.arange(n), np.arange(n)))
    apart = np.minimum(apart, n - apart) > 3  # wall parts more than 3 edges apart along the ring
    gaps = np.linalg.norm(x[:, None] - x[None], axis=-1)[apart]
    assert 0.8 * ring.thickness < gaps.min() < 1.5 * ring.thickness  # ... its walls resting on each other


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_a_deflated_ring_squashed_flat_stops_with_a_documented_error_without_the_barrier(integrator):
    """Known limit of ``Scene.self_intersection = "reject"`` (collision.py): wall parts far apart
    along a ring get no contact impulse, only the rejection of a self-crossing state. A ring without
    gas squashed flat sags until its top wall meets its bottom wall; the run must then stop at
    dt_min saying so, with finite states."""
    case = released_flat("deflated", pressure=None)
    ring = replace(case.scene.rings[0], pressure=None)
    scene = replace(case.scene, rings=[ring], integrator=integrator, self_intersection="reject")
    with pytest.raises(SimulationError, match=r"Scene\.dt_min .*a ring's wall crossed itself") as err:
        simulate(scene, case.t_end, x0=case.x0, v0=case.v0)
    result = audit(scene, case.t_end, case.x0, case.v0)
    assert result.documented and result.problems() == []
    assert err.value.trajectory.t[-1] < case.t_end
    # the halving is bounded: from the last accepted step to dt_min takes about log2(h / dt_min) tries
    assert result.rejections["self_intersection"] <= 2 * math.log2(scene.dt / scene.dt_min)


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_a_deflated_ring_squashed_flat_completes_with_the_barrier(integrator):
    """With the self-contact barrier (the default) the same ring's top wall rests on its bottom
    wall: the run reaches its end and passes the audit."""
    case = released_flat("deflated", pressure=None)
    scene = replace(case.scene, rings=[replace(case.scene.rings[0], pressure=None)], integrator=integrator)
    result = audit(scene, case.t_end, case.x0, case.v0)
    assert result.reached_end and result.problems() == []


def _violent_ring(**scene_kw):
    rng = np.random.default_rng(4)
    ring = Ring(radius=0.1, n_nodes=32, pressure=30e3, position=(0.0, 0.0))
    scene = Scene(rings=[ring], gravity=0.0, integrator="backward_euler", **scene_kw)
    return scene, 8.0 * rng.standard_normal((1, 32, 2))


def test_a_failed_newton_iteration_is_rejected_and_leaves_the_state_untouched():
    scene, v0 = _violent_ring(dt=5e-3, newton_max_iter=1)
    model, solver, ws = build_model(scene), build_solver(scene), build_workspace(32)
    state, trial = empty_state(1, 32), empty_state(1, 32)
    from ballenv.physics.build import initial_state

    state.x[:] = initial_state(scene)[0]
    state.v[:] = v0
    initial_state_values(model, solver, state, ws)
    before = [a.copy() for a in state]
    its, impulse_ratio, error = try_step(model, solver, state, trial, 0.0, 5e-3, ws)
    assert its == -REJECT_NEWTON and impulse_ratio == 0.0 and error == 0.0
    for old, new in zip(before, state, strict=True):
        np.testing.assert_array_equal(old, new)


def test_every_accepted_step_is_a_converged_step():
    """With at most 3 Newton corrections many steps fail; every accepted one must still be the
    converged implicit step: re-solving it from the previous record with 50 corrections allowed
    gives the same state (backward Euler needs only x, v)."""
    scene, v0 = _violent_ring(dt=2e-3, adaptive=True, newton_max_iter=3)
    traj = simulate(scene, 0.02, v0=v0)
    assert traj.stats.rejections["newton"] > 0
    strict = replace(scene, newton_max_iter=50)
    model, solver, ws = build_model(strict), build_solver(strict), build_workspace(32)
    state, trial = empty_state(1, 32), empty_state(1, 32)
    for k in range(len(traj.t) - 1):
        state.x[:] = traj.x[k]
        state.v[:] = traj.v[k]
        initial_state_values(model, solver, state, ws)
        its, _, _ = try_step(model, solver, state, trial, traj.t[k], traj.t[k + 1] - traj.t[k], ws)
        assert its >= 0
        scale = np.abs(traj.x[k + 1]).max()
        np.testing.assert_allclose(trial.x, traj.x[k + 1], rtol=0, atol=1e-9 * scale)


def test_below_the_minimum_step_a_clear_error_instead_of_endless_halving():
    scene, v0 = _violent_ring(
        dt=2e-3, dt_min=1e-6, adaptive=True, newton_max_iter=1, newton_rescue_max_iter=0
    )
    with pytest.raises(SimulationError) as err:
        simulate(scene, 0.02, v0=v0)
    message = str(err.value)
    assert "Scene.dt_min = 1e-06 s" in message and "Newton's iteration did not converge" in message
    traj = err.value.trajectory
    assert np.all(np.isfinite(traj.x))
    # between two accepted steps (and before the error) at most log2(dt / dt_min) + 1 halvings
    halvings = math.ceil(math.log2(2e-3 / 1e-6)) + 1
    assert traj.stats.rejected_steps <= (traj.stats.steps + 1) * halvings
    assert traj.stats.wall_time < 10.0


def test_ground_contact_on_both_sides_of_a_wedge_stays_out_of_both():
    """A ball dropped into a 90 degree V (two 45 degree slopes): contact with two grounds at once."""
    grounds = [Ground(angle=math.radians(45), friction=0.5), Ground(angle=-math.radians(45), friction=0.5)]
    for contact in CONTACTS:
        for integrator in INTEGRATORS:
            ring = Ring(radius=0.1, n_nodes=32, position=(0.0, 0.5))
            scene = Scene(rings=[ring], grounds=grounds, contact=contact, integrator=integrator,
                          dt=1e-2, adaptive=True)  # fmt: skip
            result = audit(scene, 0.6)
            assert result.problems() == [] and result.reached_end, (contact, integrator, result)


@pytest.mark.parametrize("integrator", INTEGRATORS)
@pytest.mark.parametrize("contact", CONTACTS)
def test_a_heavy_ring_sliding_in_at_speed_meets_the_impulse_tolerance(contact, integrator):
    """Regression (found by the soak): the Coulomb friction on a node arriving while it slides is
    about mu m |v_n| whatever the step, like the normal impulse that stops it; it was counted in the
    contact impulse, so this scene (mu m v_n = 0.65 N s per node against impulse_tol = 5e-3 N s)
    stopped with "contact impulse above impulse_tol at dt_min" at the first touchdown."""
    ring = Ring(radius=0.1, n_nodes=32, youngs_modulus=1e8, thickness=1e-2, width=0.05, density=3000.0,
                pressure=1e5, position=(0.0, 0.2), velocity=(10.0, -15.0))  # fmt: skip
    scene = Scene(rings=[ring], grounds=[Ground(friction=1.5)], contact=contact, integrator=integrator,
                  dt=1e-2, adaptive=True, impulse_tol=5e-3)  # fmt: skip
    result = audit(scene, 0.1)
    assert result.problems() == [] and result.reached_end, result
    assert result.rejections["impulse"] > 0  # the step control did act


def test_a_newton_iterate_turned_inside_out_is_taken_back_not_a_crash():
    """Regression (found by the soak, scene 574 of seed 0): a first backward-Euler step of 8 ms of a
    ring hitting the ground at 37 m/s gave a Newton iterate of zero area; the gas law divided by
    A^k = 0 and numba raised ZeroDivisionError out of simulate(). The gas kernels now return NaN
    for A <= 0, which the Newton loop takes back (backtracking) or rejects."""
    from ballenv.physics.effects.gas import gas_energy, gas_pressure, gas_pressure_slope

    for area in (0.0, -1e-3):
        assert math.isnan(gas_pressure(area, 1e3, 1.4, 0.0))
        assert math.isnan(gas_pressure_slope(area, 1e3, 1.4))
        assert math.isnan(gas_energy(area, 1e3, 1.0, 101325.0, 0.02))
    ring = Ring(radius=0.0703, n_nodes=128, youngs_modulus=9.93e7, thickness=0.01324, width=0.02707,
                density=2981.9, pressure=609337.0, position=(0.0, 0.0907289), velocity=(26.5026, -26.2547),
                angular_velocity=-17.59)  # fmt: skip
    scene = Scene(rings=[ring], grounds=[Ground(friction=0.488)], contact="predictor_corrector",
                  gravity=8.46, damping=5.0, integrator="backward_euler", dt=0.00827, adaptive=True,
                  impulse_tol=5e-3, atmospheric_pressure=0.0, gas_exponent=1.4)  # fmt: skip
    result = audit(scene, 0.03)
    assert result.problems() == [] and result.reached_end, result


def test_resting_nodes_pushed_into_the_ground_by_self_contact_meet_the_impulse_tolerance():
    """Regression (found by the soak, scene 42 of seed 0): a thin-walled ring skidding at 27 m/s
    and 43 rad/s folds its wall at the edge of its contact patch; the self-contact impulse of the
    folding node pushed two nodes resting on the ground into it at 5 m/s, and the reaction that
    stops them (8.3e-3 N s at any step from 1e-5 to 1e-9 s) was counted in the contact impulse: the
    run stopped with "contact impulse above impulse_tol at dt_min" at t = 10 ms. The stopping
    reaction is now netted out for every constrained node, as for arriving ones."""
    ring = Ring(radius=0.06951, n_nodes=64, youngs_modulus=3.41411e6, thickness=6.8264e-4, width=0.06217,
                density=2565.08, pressure=87.2228, position=(0.036073, 0.2130004),
                velocity=(-27.03035, -14.01605), angular_velocity=-43.37882)  # fmt: skip
    scene = Scene(rings=[ring], grounds=[Ground(angle=-0.1677661, friction=0.08312)], gravity=1.48515,
                  integrator="generalized_alpha", rho_infinity=0.18383, dt=0.0087369, adaptive=True,
                  impulse_tol=5e-3, atmospheric_pressure=101325.0, gas_exponent=1.4)  # fmt: skip
    result = audit(scene, 0.1067)
    assert result.problems() == [] and result.reached_end, result
    assert result.rejections["impulse"] > 0
