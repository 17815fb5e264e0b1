"""Fidelity presets: named accuracy-for-cost settings of the numerical method, each defined by the
accuracy it asks for.

Each preset sets the node count of every ring and the step control of the scene; the physics
(material, pressure, effects) is untouched. All are generalized-alpha with ``rho_infinity = 0.3``
whose adaptive step keeps the error within the relative tolerance ``rtol`` (``Scene.rtol``: the
integrator's local error estimate on the nodes' positions at most ``rtol R``, and the contact
impulse per step at most ``rtol M sqrt(g R)``, ``M`` the ring's mass and ``R`` its radius):

=========  ======  =====  ==========  ==========  ===========================
preset     nodes   rtol   largest dt  newton_tol  first-apex error (bound)
=========  ======  =====  ==========  ==========  ===========================
fast       32      0.1    0.02 s      1e-6        3 %
balanced   64      0.02   0.01 s      1e-9        1 %
accurate   128     0.003  0.005 s     1e-10       0.3 %
=========  ======  =====  ==========  ==========  ===========================

The bound is on the error of the step control: the first-apex height of each of the six balls of
``benchmarks/ball_family.py`` (3 g to 500 g, gas-to-bending stiffness ratio 1.9 to 7,800, flat
floor and slope, with and without friction) against a converged run of the same ball at the same
node count. ``tests/physics/test_presets.py`` checks every preset's bound on every ball;
``benchmarks/accuracy.py`` measures the errors and the wall time of a 1-s drop
(``benchmarks/results/accuracy.md``). The node count is a separate choice with its own error, the
polygon's, which the same page gives for every ball. ``rho_infinity = 0.3`` (the Scene default is
0.9) damps the wall's modes above what the step resolves, which would otherwise cost Newton
iterations and rejected steps.

InflatedBall-v3's ``fidelity`` keyword keeps the settings its dynamics were defined with
(:mod:`ballenv.envs.numerics`).
"""

import dataclasses
from typing import Any

from .scene import Scene, check_choice

PRESET_RHO_INFINITY = 0.3  # generalized-alpha's high-frequency damping in every preset

FIDELITY_PRESETS: dict[str, dict[str, Any]] = {
    "fast": {"n_nodes": 32, "rtol": 0.1, "dt": 2e-2, "newton_tol": 1e-6, "apex_error_bound": 0.03},
    "balanced": {"n_nodes": 64, "rtol": 0.02, "dt": 1e-2, "newton_tol": 1e-9, "apex_error_bound": 0.01},
    "accurate": {"n_nodes": 128, "rtol": 3e-3, "dt": 5e-3, "newton_tol": 1e-10, "apex_error_bound": 0.003},
}


def with_fidelity(scene: Scene, fidelity: str) -> Scene:
    """``scene`` with the numerical settings of preset ``fidelity`` ("fast" | "balanced" | "accurate")."""
    check_choice("with_fidelity", "fidelity", fidelity, tuple(FIDELITY_PRESETS))
    if not isinstance(scene, Scene):
        raise ValueError(f"with_fidelity.scene = {scene!r} is invalid: must be a ballenv.physics.Scene")
    preset = FIDELITY_PRESETS[fidelity]
    return with_numerics(
        scene,
        preset["n_nodes"],
        integrator="generalized_alpha",
        adaptive=True,
        rtol=preset["rtol"],
        impulse_tol=None,  # the preset's rtol sets the contact bound, whatever the scene had
        contact_error="impulse",
        dt=preset["dt"],
        newton_tol=preset["newton_tol"],
        rho_infinity=PRESET_RHO_INFINITY,
    )


def with_numerics(scene: Scene, n_nodes: int, **numerics: Any) -> Scene:
    """``scene`` with every ring at ``n_nodes`` nodes and the Scene fields ``numerics``; the physics
    (material, pressure, effects) untouched."""
    rings = tuple(dataclasses.replace(r, n_nodes=n_nodes) for r in scene.rings)
    return dataclasses.replace(scene, rings=rings, **numerics)
