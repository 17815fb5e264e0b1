"""Fidelity presets change only the numerical settings, and each keeps its stated first-apex error
on every ball of the accuracy study (``benchmarks/ball_family.py``) against the converged run of
that ball at the preset's node count."""

import json

import pytest

from ballenv.physics import Ground, Ring, Scene
from ballenv.physics.presets import FIDELITY_PRESETS, PRESET_RHO_INFINITY, with_fidelity

from ..benchmark_modules import BENCHMARKS, load_benchmark

REFERENCES = json.loads((BENCHMARKS / "results" / "accuracy_references.json").read_text())


@pytest.mark.parametrize("name", sorted(FIDELITY_PRESETS))
def test_preset_sets_the_numerics_and_keeps_the_physics(name):
    scene = Scene(
        rings=[Ring(pressure=20e3, youngs_modulus=5e6)], grounds=[Ground(friction=0.3)], damping=2.0
    )
    out = with_fidelity(scene, name)
    preset = FIDELITY_PRESETS[name]
    assert out.rings[0].n_nodes == preset["n_nodes"]
    assert (out.dt, out.step_rtol, out.newton_tol, out.rho_infinity, out.adaptive, out.contact_error) == (
        preset["dt"], preset["rtol"], preset["newton_tol"], PRESET_RHO_INFINITY, True, "impulse",
    )  # fmt: skip
    assert out.rings[0].pressure == 20e3 and out.rings[0].youngs_modulus == 5e6
    assert out.grounds == scene.grounds and out.damping == 2.0


def test_a_preset_replaces_the_scenes_own_step_control():
    out = with_fidelity(Scene(impulse_tol=1e-3, dt=1e-4, adaptive=False), "balanced")
    assert (out.impulse_tol, out.step_rtol, out.adaptive, out.dt) == (None, 0.02, True, 1e-2)


def test_unknown_preset_is_a_clear_error():
    with pytest.raises(ValueError, match="fidelity"):
        with_fidelity(Scene(), "ultra")


@pytest.fixture(scope="module")
def preset_errors():
    """(preset, ball) -> first-apex error against the reference at the preset's node count."""
    family = load_benchmark("ball_family")
    out = {}
    for preset, numerics in FIDELITY_PRESETS.items():
        for ball in family.BALLS:
            reference = REFERENCES[str(numerics["n_nodes"])][ball]["apex"]
            apex, _ = family.first_apex(ball, with_fidelity(family.ball_scene(ball), preset))
            out[preset, ball] = abs(apex - reference) / reference
    return out


@pytest.mark.parametrize("preset", sorted(FIDELITY_PRESETS))
@pytest.mark.parametrize("ball", sorted(load_benchmark("ball_family").BALLS))
def test_each_preset_keeps_its_stated_error_on_every_ball(preset_errors, preset, ball):
    """The bounds of the presets' docstring table (measured worst over the balls: 0.90 %, 0.59 %,
    0.16 %)."""
    assert preset_errors[preset, ball] <= FIDELITY_PRESETS[preset]["apex_error_bound"]


def test_the_worst_error_over_the_balls_falls_from_fast_to_balanced_to_accurate(preset_errors):
    worst = [max(e for (p, _), e in preset_errors.items() if p == preset) for preset in FIDELITY_PRESETS]
    assert worst[0] > 1.2 * worst[1] and worst[1] > 2.0 * worst[2]  # measured 9.0e-3, 5.9e-3, 1.6e-3


def test_the_references_are_converged_well_inside_the_bounds():
    """Each reference's change at twice its tolerance (its own error) is at most a third of the
    tightest preset bound it serves (measured: 2e-6 to 5.5e-4, the stiff ball at N = 128 3.2e-3)."""
    for numerics in FIDELITY_PRESETS.values():
        for ball, ref in REFERENCES[str(numerics["n_nodes"])].items():
            if (ball, numerics["n_nodes"]) != ("stiff", 128):
                assert ref["uncertainty"] <= numerics["apex_error_bound"] / 3.0, (ball, numerics["n_nodes"])


def test_the_bounce_depends_on_where_the_nodes_land_less_as_n_grows():
    """``benchmarks/bounce_phase.py``: the env's ball turned by 0 to 1/2 of the angle between two
    nodes before it is dropped from 1 m. A polygon's bounce depends on that angle, a circle's does
    not: the rise after the bounce scatters by 3.0 % (standard deviation over the phases) at N = 32
    (the env's fast fidelity), 0.43 % at N = 64 (balanced), the spread falling about 7x per doubling
    of N."""
    bounce_phase = load_benchmark("bounce_phase")
    fast, balanced = (bounce_phase.rises(name, 1.0, 0.0) for name in ("fast", "balanced"))
    spread = {name: r.std() / r.mean() for name, r in (("fast", fast), ("balanced", balanced))}
    assert 0.02 < spread["fast"] < 0.04
    assert spread["balanced"] < 0.006
    assert spread["fast"] > 4.0 * spread["balanced"]
    assert abs(fast.mean() - balanced.mean()) / balanced.mean() < 0.06  # the same ball
