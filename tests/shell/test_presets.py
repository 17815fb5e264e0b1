"""The 3-D ball's fidelity presets change only the numerical settings, and each keeps its stated
first-apex error on every ball of ``benchmarks/shell_presets.py`` against the converged run of
that ball on the preset's mesh (``benchmarks/results/shell_references.json``)."""

import json

import pytest

from ballenv.shell import Ground, Scene, Shell
from ballenv.shell.presets import FIDELITY_PRESETS, PRESET_RHO_INFINITY, with_fidelity

from ..benchmark_modules import BENCHMARKS, load_benchmark

REFERENCES = json.loads((BENCHMARKS / "results" / "shell_references.json").read_text())
BALLS = sorted(load_benchmark("shell_presets").BALLS)


@pytest.mark.parametrize("name", sorted(FIDELITY_PRESETS))
def test_preset_sets_the_numerics_and_keeps_the_physics(name):
    scene = Scene(
        shells=[Shell(pressure=20e3, youngs_modulus=2e6), Shell(position=(1, 0, 1))],
        grounds=[Ground(friction=0.3)], damping=2.0, integrator="backward_euler", adaptive=False,
    )  # fmt: skip
    out = with_fidelity(scene, name)
    preset = FIDELITY_PRESETS[name]
    assert {s.subdivisions for s in out.shells} == {preset["subdivisions"]}
    assert (out.integrator, out.rho_infinity, out.adaptive) == (
        "generalized_alpha",
        PRESET_RHO_INFINITY,
        True,
    )
    assert (out.rtol, out.dt, out.newton_tol) == (preset["rtol"], preset["dt"], preset["newton_tol"])
    assert out.shells[0].pressure == 20e3 and out.shells[0].youngs_modulus == 2e6
    assert out.shells[1].position == (1.0, 0.0, 1.0)
    assert out.grounds == scene.grounds and out.damping == 2.0


def test_an_unknown_preset_or_scene_is_a_clear_error():
    with pytest.raises(ValueError, match="fidelity"):
        with_fidelity(Scene(), "ultra")
    with pytest.raises(ValueError, match="ballenv.shell.Scene"):
        with_fidelity("scene", "fast")


def preset_error(preset, ball):
    bench = load_benchmark("shell_presets")
    apex, _ = bench.first_apex(with_fidelity(bench.ball_scene(ball), preset))
    reference = REFERENCES[str(FIDELITY_PRESETS[preset]["subdivisions"])][ball]
    return abs(apex - reference) / reference


@pytest.mark.parametrize(
    "preset", ["fast", "balanced", pytest.param("accurate", marks=pytest.mark.slow)]
)  # accurate: 2562 vertices, about a minute a ball
@pytest.mark.parametrize("ball", BALLS)
def test_each_preset_keeps_its_stated_error_on_every_ball(preset, ball):
    assert preset_error(preset, ball) <= FIDELITY_PRESETS[preset]["apex_error_bound"]
