"""Fidelity presets change only the numerical settings."""

import pytest

from ballenv.physics import Ground, Ring, Scene
from ballenv.physics.presets import FIDELITY_PRESETS, with_fidelity

from ..benchmark_modules import load_benchmark


@pytest.mark.parametrize("name", sorted(FIDELITY_PRESETS))
def test_preset_sets_the_numerics_and_keeps_the_physics(name):
    scene = Scene(
        rings=[Ring(pressure=20e3, youngs_modulus=5e6)], grounds=[Ground(friction=0.3)], damping=2.0
    )
    out = with_fidelity(scene, name)
    preset = FIDELITY_PRESETS[name]
    assert out.rings[0].n_nodes == preset["n_nodes"]
    assert (out.dt, out.impulse_tol, out.newton_tol, out.rho_infinity, out.adaptive) == (
        preset["dt"], preset["impulse_tol"], preset["newton_tol"], preset["rho_infinity"], True,
    )  # fmt: skip
    assert out.rings[0].pressure == 20e3 and out.rings[0].youngs_modulus == 5e6
    assert out.grounds == scene.grounds and out.damping == 2.0


def test_unknown_preset_is_a_clear_error():
    with pytest.raises(ValueError, match="fidelity"):
        with_fidelity(Scene(), "ultra")


# first-apex error bounds on the single-bounce scene of benchmarks/work_precision.py, as the README states
README_APEX_ERROR_BOUNDS = {"fast": 0.05, "balanced": 0.005, "accurate": 0.003}


def _work_precision():
    return load_benchmark("work_precision")


@pytest.fixture(scope="module")
def single_bounce_errors():
    wp = _work_precision()
    reference = wp.reference("bounce")  # N = 256, impulse_tol = 1e-4 N s, dt <= 1e-3 s
    out = {}
    for name in FIDELITY_PRESETS:
        run = wp.run(wp.preset_scene("bounce", name), wp.SCENES["bounce"], repeats=1)
        out[name] = wp.errors(run.obs, reference.obs)
    return out


@pytest.mark.parametrize("name", sorted(FIDELITY_PRESETS))
def test_preset_first_apex_error_is_within_the_readme_bound(single_bounce_errors, name):
    assert single_bounce_errors[name]["apex"] < README_APEX_ERROR_BOUNDS[name]


def test_balanced_preset_meets_the_one_percent_target_and_fast_is_coarser(single_bounce_errors):
    assert single_bounce_errors["balanced"]["apex"] < 0.01
    assert single_bounce_errors["fast"]["apex"] > 3 * single_bounce_errors["balanced"]["apex"]


def test_the_bounce_depends_on_where_the_nodes_land_less_as_n_grows():
    """``benchmarks/bounce_phase.py``: the env's ball turned by 0 to 1/2 of the angle between two
    nodes before it is dropped from 1 m. A polygon's bounce depends on that angle, a circle's does
    not: the rise after the bounce scatters by 3.0 % (standard deviation over the phases) at N = 32
    (fast), 0.43 % at N = 64 (balanced), the spread falling about 7x per doubling of N."""
    bounce_phase = load_benchmark("bounce_phase")
    fast, balanced = (bounce_phase.rises(name, 1.0, 0.0) for name in ("fast", "balanced"))
    spread = {name: r.std() / r.mean() for name, r in (("fast", fast), ("balanced", balanced))}
    assert 0.02 < spread["fast"] < 0.04
    assert spread["balanced"] < 0.006
    assert spread["fast"] > 4.0 * spread["balanced"]
    assert abs(fast.mean() - balanced.mean()) / balanced.mean() < 0.06  # the same ball
