"""Ring and Scene validate every value on construction, naming the field, the value and the range."""

import math

import pytest

from ballenv.physics import Ring, Scene, simulate
from ballenv.physics.build import scene_effects
from ballenv.physics.scene import DEFAULT_RTOL
from ballenv.physics.step.integrator import build_solver


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"youngs_modulus": -1.0}, "youngs_modulus"),
        ({"youngs_modulus": math.nan}, "youngs_modulus"),
        ({"n_nodes": 2}, "n_nodes"),
        ({"n_nodes": 16.0}, "n_nodes"),
        ({"thickness": 0.1}, "thickness"),
        ({"thickness": 0.2}, "thickness"),
        ({"radius": 0.0}, "radius"),
        ({"radius": math.inf}, "radius"),
        ({"density": -5.0}, "density"),
        ({"width": 0.0}, "width"),
        ({"pressure": -2.1e5}, "pressure"),  # -E h / (R cos(pi/N)) compresses the wall by 50 %
        ({"pressure": math.nan}, "pressure"),
        ({"pressure": 1.1e5}, "pressure"),  # E h / (2 R) = 1e5 Pa would stretch the wall by 100 %
        ({"position": (0.0, math.nan)}, "position"),
        ({"position": (0.0, 1.0, 2.0)}, "position"),
        ({"velocity": "fast"}, "velocity"),
        ({"angular_velocity": math.inf}, "angular_velocity"),
    ],
)
def test_ring_rejects_invalid_values(kwargs, field):
    with pytest.raises(ValueError, match=rf"Ring\.{field} = .* must be"):
        Ring(**kwargs)


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"rings": []}, "rings"),
        ({"rings": [1.0]}, "rings"),
        ({"rings": [Ring(n_nodes=8), Ring(n_nodes=16)]}, "rings"),
        ({"gravity": -9.81}, "gravity"),
        ({"gravity": (0.0, math.nan)}, "gravity"),
        ({"damping": -1.0}, "damping"),
        ({"damping_mode": "viscous"}, "damping_mode"),
        ({"integrator": "rk4"}, "integrator"),
        ({"rho_infinity": 1.5}, "rho_infinity"),
        ({"dt": 0.0}, "dt"),
        ({"dt": 1e-3, "dt_min": 1e-2}, "dt_min"),
        ({"adaptive": 1}, "adaptive"),
        ({"newton_tol": 0.5}, "newton_tol"),
        ({"newton_max_iter": 0}, "newton_max_iter"),
        ({"newton_rescue_max_iter": -1}, "newton_rescue_max_iter"),
        ({"newton_rescue_max_iter": 201}, "newton_rescue_max_iter"),
        ({"atmospheric_pressure": -1.0}, "atmospheric_pressure"),
        ({"gas_exponent": -0.5}, "gas_exponent"),
        ({"gas_exponent": 3.5}, "gas_exponent"),
        ({"rings": [Ring(pressure=-1.5e5)]}, r"rings\[0\]\.pressure"),
        ({"rings": [Ring(), Ring(pressure=-1.0)], "atmospheric_pressure": 0.0}, r"rings\[1\]\.pressure"),
    ],
)
def test_scene_rejects_invalid_values(kwargs, field):
    with pytest.raises(ValueError, match=rf"Scene\.{field} = .* must be"):
        Scene(**kwargs)


def test_negative_gauge_pressure_keeps_the_absolute_pressure_positive():
    assert Scene(rings=[Ring(pressure=-101e3)]).rings[0].pressure == -101e3
    with pytest.raises(ValueError) as err:
        Scene(rings=[Ring(pressure=-2e4)], atmospheric_pressure=1e4)
    assert str(err.value) == (
        "Scene.rings[0].pressure = -20000.0 is out of range: must be a finite number in (-10000, 100121]"
        " Pa; the absolute pressure p + Scene.atmospheric_pressure must stay positive"
    )


def test_error_message_names_value_and_range():
    with pytest.raises(ValueError) as err:
        Ring(youngs_modulus=-1.0)
    assert str(err.value) == (
        "Ring.youngs_modulus = -1.0 is out of range: must be a finite number in (0, 1e+12] Pa"
    )


def test_the_default_step_is_adaptive_under_error_control():
    scene = Scene()
    assert scene.adaptive and scene.dt == 1e-2 and scene.step_rtol == DEFAULT_RTOL == 1e-2
    assert scene.contact_error == "impulse" and scene.rho_infinity == 0.9  # benchmarks/accuracy.py's row
    assert build_solver(scene).rtol == DEFAULT_RTOL
    assert Scene(adaptive=False).dt == 1e-2 and build_solver(Scene(adaptive=False)).rtol == 0.0


def test_an_impulse_bound_alone_turns_error_control_off_and_both_are_a_clear_error():
    assert Scene(impulse_tol=2e-3).step_rtol == 0.0
    assert Scene(rtol=1e-3).step_rtol == 1e-3
    assert Scene(rtol=0.0, impulse_tol=2e-3).step_rtol == 0.0  # the env's form
    with pytest.raises(ValueError) as err:
        Scene(rtol=1e-3, impulse_tol=2e-3)
    assert str(err.value).startswith("Scene.impulse_tol = 0.002 is invalid with Scene.rtol = 0.001: give one")
    with pytest.raises(ValueError, match=r"Scene\.impulse_tol = None is invalid with Scene\.rtol = 0"):
        Scene(rtol=0.0)
    assert Scene(rtol=0.0, adaptive=False).step_rtol == 0.0  # fixed steps need no bound


@pytest.mark.parametrize("t_end", [0.0, -1.0, math.nan, "1"])
def test_simulate_rejects_invalid_t_end(t_end):
    with pytest.raises(ValueError, match=r"simulate\.t_end"):
        simulate(Scene(), t_end)


def test_simulate_rejects_wrong_initial_state_shape_and_nan():
    scene = Scene(rings=[Ring(n_nodes=8)])
    with pytest.raises(ValueError, match=r"simulate\.x0 has shape"):
        simulate(scene, 0.01, x0=[[0.0, 0.0]])
    with pytest.raises(ValueError, match=r"simulate\.v0 contains NaN"):
        simulate(scene, 0.01, v0=[[math.nan, 0.0]] * 8)


def test_effects_name_only_what_the_scene_asks_for():
    bare = Scene(rings=[Ring(pressure=None)], gravity=0.0)
    assert scene_effects(bare) == ("stretching", "bending")
    full = Scene(rings=[Ring(pressure=0.0)], gravity=9.81, damping=1.0)
    assert scene_effects(full) == ("stretching", "bending", "pressure", "gravity", "damping")
