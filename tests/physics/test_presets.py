"""Fidelity presets change only the numerical settings."""

import pytest

from ballenv.physics import Ground, Ring, Scene
from ballenv.physics.presets import FIDELITY_PRESETS, with_fidelity


@pytest.mark.parametrize("name", sorted(FIDELITY_PRESETS))
def test_preset_sets_the_numerics_and_keeps_the_physics(name):
    scene = Scene(
        rings=[Ring(pressure=20e3, youngs_modulus=5e6)], grounds=[Ground(friction=0.3)], damping=2.0
    )
    out = with_fidelity(scene, name)
    preset = FIDELITY_PRESETS[name]
    assert out.rings[0].n_nodes == preset["n_nodes"]
    assert (out.dt, out.impulse_tol, out.newton_tol, out.adaptive) == (
        preset["dt"], preset["impulse_tol"], preset["newton_tol"], True,
    )  # fmt: skip
    assert out.rings[0].pressure == 20e3 and out.rings[0].youngs_modulus == 5e6
    assert out.grounds == scene.grounds and out.damping == 2.0


def test_unknown_preset_is_a_clear_error():
    with pytest.raises(ValueError, match="fidelity"):
        with_fidelity(Scene(), "ultra")
