"""The work-precision benchmark (benchmarks/work_precision.py) in reduced form: convergence orders of
both integrators in flight, and a few points of the single-bounce sweep against its reference."""

import numpy as np
import pytest

from ...benchmark_modules import load_benchmark

wp = load_benchmark("work_precision")
FLIGHT_DTS = np.array([1e-4, 5e-5, 2.5e-5, 1.25e-5])


@pytest.mark.parametrize(("integrator", "order"), [("backward_euler", 1), ("generalized_alpha", 2)])
def test_convergence_order_in_flight(integrator, order):
    # the ball in flight, released ovalised: first order for backward Euler, second for generalized-alpha
    errors = wp.flight_errors(integrator, FLIGHT_DTS)
    assert wp.fitted_order(FLIGHT_DTS, errors) == pytest.approx(order, abs=0.1)
    assert np.all(errors[:-1] / errors[1:] == pytest.approx(2.0**order, rel=0.1))
    assert errors[-1] < (1e-7 if order == 2 else 3e-5)  # m, after 10 ms


@pytest.fixture(scope="module")
def bounce_reference():
    return wp.reference("bounce")


def _bounce(reference, **numerics):
    r = wp.run(wp.configured(wp.base_scene("bounce"), **numerics), wp.SCENES["bounce"], repeats=1)
    r.errors = wp.errors(r.obs, reference.obs)
    return r


def test_reduced_single_bounce_sweep(bounce_reference):
    ref = bounce_reference.obs
    # the reference itself is physical: the ball bounces back with 0.8 < e < 0.95 after ~13 ms
    assert 0.75 < ref["apex"] < 0.85 and 0.8 < ref["cor"] < 0.95 and 0.01 < ref["contact"] < 0.02
    ga = {tol: _bounce(bounce_reference, adaptive=True, dt=1e-2, impulse_tol=tol) for tol in (5e-3, 1e-3)}
    be = {
        dt: _bounce(bounce_reference, integrator="backward_euler", adaptive=False, dt=dt)
        for dt in (5e-4, 1.25e-4)
    }
    for runs in (ga, be):
        coarse, fine = runs.values()
        assert fine.errors["apex"] < 0.5 * coarse.errors["apex"]
        assert fine.errors["com_l2"] < 0.5 * coarse.errors["com_l2"]
    # backward Euler's damping: its first apex converges at about first order in dt through contact
    ratio = be[5e-4].errors["apex"] / be[1.25e-4].errors["apex"]
    assert 2.5 < ratio < 5.0
    # generalized-alpha with the adaptive step: > 10x more accurate in < 1/10 of the steps
    assert ga[1e-3].errors["apex"] < 0.1 * be[1.25e-4].errors["apex"]
    assert ga[1e-3].steps < 0.1 * be[1.25e-4].steps
    assert ga[1e-3].errors["apex"] < 5e-3
    runs = {"GA MM adaptive": list(ga.items()), "BE MM fixed": list(be.items())}
    front = wp.pareto(runs)
    assert [curve for curve, _, _ in front] == ["GA MM adaptive"] * len(front)


def test_backward_euler_damping_inverts_the_restitution_trend_that_converged_runs_show():
    # the physics view of the benchmark: restitution rises with inflation pressure; BE at a 1 ms step
    # damps the stiffer ball's ringing more and shows the opposite trend, a fine BE step recovers it
    low, high = 10e3, 60e3
    converged = wp.COR_SETTINGS["GA adaptive tol=1e-4 (converged)"]
    coarse_be = wp.COR_SETTINGS["BE dt=0.001"]
    fine_be = wp.COR_SETTINGS["BE dt=6.25e-05"]
    assert wp.restitution(high, converged) > wp.restitution(low, converged) + 0.05
    assert wp.restitution(high, coarse_be) < wp.restitution(low, coarse_be) - 0.05
    assert wp.restitution(high, fine_be) > wp.restitution(low, fine_be) + 0.03


def test_single_bounce_reference_converges_in_the_step_and_to_about_a_tenth_of_a_percent_in_n(
    bounce_reference,
):
    # the README's statement of the reference's own convergence (halved step control; doubled N)
    ref = bounce_reference.obs
    refined = wp.errors(wp.reference("bounce", impulse_tol=5e-5, dt=5e-4).obs, ref)
    doubled = wp.errors(wp.reference("bounce", n_nodes=512).obs, ref)
    assert refined["apex"] < 1e-4 and refined["cor"] < 1e-4
    assert doubled["apex"] < 2e-3 and doubled["cor"] < 1e-3
