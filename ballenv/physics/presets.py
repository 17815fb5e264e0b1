"""Fidelity presets: named accuracy-for-cost settings of the numerical method, each defined by the
accuracy it asks for.

Each preset sets the node count of every ring and the step control of the scene; the physics
(material, pressure, effects) is untouched. All are generalized-alpha with ``rho_infinity = 0.3``
whose adaptive step keeps the error within the relative tolerance ``rtol`` (``Scene.rtol``: the
integrator's local error estimate on the nodes' positions at most ``rtol R``, and the contact
impulse per step at most ``rtol M sqrt(g R)``, ``M`` the ring's mass and ``R`` its radius):

=========  ======  =====  ==========  ==========  ====================  ==================  ===========
preset     nodes   rtol   largest dt  newton_tol  first-apex error      measured worst      wall, 1 s
=========  ======  =====  ==========  ==========  ====================  ==================  ===========
fast       32      0.1    0.02 s      1e-6        bound 3 %             0.9 %               4-10 ms
balanced   64      0.02   0.01 s      1e-9        bound 1 %             0.6 %               21-59 ms
accurate   128     0.003  0.005 s     1e-10       bound 0.3 %           0.16 %              161-610 ms
=========  ======  =====  ==========  ==========  ====================  ==================  ===========

The error is that of the step control: the first-apex height of the six balls of
``benchmarks/ball_family.py`` (3 g to 500 g, gas-to-bending stiffness ratio 1.9 to 7,800, flat
floor and slope, with and without friction) against a converged run of the same ball at the same
node count; ``benchmarks/accuracy.py`` measures it (with the wall time of the 1-s drop) and
``tests/physics/test_presets.py`` checks every preset's bound on every ball. The node count is a
separate choice with its own error, the polygon's: the converged first apex moves by up to 5 %
from N = 32 to N = 64 and up to 1.2 % from 64 to 128 (the bending-dominated ball; the table
``benchmarks/results/accuracy.md`` gives every ball's). ``rho_infinity = 0.3`` (the Scene default
is 0.9) damps the wall's modes above what the step resolves, which cost Newton iterations and
rejected steps when left ringing: at N = 64 and the same ``rtol`` the runs take 1.5-2x less wall
time than with 0.9, and the worst error over the six balls differs by at most 2.7x either way
(0.85 / 0.26 / 0.33 % against 0.72 / 0.70 / 0.14 % at rtol 0.03 / 0.01 / 0.003).

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
