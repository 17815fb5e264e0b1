"""Fidelity presets: named accuracy-for-cost settings of the numerical method.

Each preset sets the node count of every ring and the step control of the scene; the physics
(material, pressure, effects) is untouched. All are generalized-alpha with ``rho_infinity = 0.3``
and the step adapted to the contact impulse (``Scene.adaptive``):

=========  ======  ===========  ================  ============  ====================  ===========
preset     nodes   largest dt   impulse_tol       newton_tol    first-apex error      wall, 0.9 s
=========  ======  ===========  ================  ============  ====================  ===========
fast       32      0.02 s       0.01 N s          1e-6          1.3 % (bound 5 %)     6-8 ms
balanced   64      0.01 s       0.002 N s         1e-9          0.34 % (bound 0.5 %)  23-30 ms
accurate   128     0.005 s      0.0005 N s        1e-10         0.02 % (bound 0.3 %)  113-140 ms
=========  ======  ===========  ================  ============  ====================  ===========

Errors and wall times are measured by ``benchmarks/work_precision.py`` on its single-bounce scene
(the env's ball dropped from 1 m onto flat ground) against a reference at N = 256 whose own
uncertainty is 0.11 % (doubling N moves it by that much); ``tests/physics/test_presets.py`` checks
the bounds. The node counts are the env's observation sizes. ``rho_infinity = 0.3`` (the Scene
default is 0.9) damps the wall's modes above what the step resolves: at the presets' steps (10-20 ms,
longer than the 8 ms breathing period) the lightly damped 0.9 left them ringing, which cost Newton
iterations and rejected steps (energy guard, self-crossing), and made the first apex *less*
accurate (fast 3.2 %, balanced 0.22 %, accurate 0.12 % at 0.9). Measured with
``benchmarks/env_profile.py`` on random actions, 0.9 -> 0.3: fast 39 -> 8 Newton iterations per
pressure-mode control step and 49 -> 19 per paddle-mode one; ``rho_infinity = 0`` saves a little
more (7 and 19) but doubles the restitution error of the bouncing scene. A tighter ``impulse_tol``
for fast (5e-3 N s) was not taken: violent paddle strikes in the env then end in "impulse above
impulse_tol at dt_min" simulator failures. Wall times: range over runs of the benchmark.
"""

import dataclasses
from typing import Any

from .scene import Scene, check_choice

FIDELITY_PRESETS: dict[str, dict[str, Any]] = {
    "fast": {"n_nodes": 32, "dt": 2e-2, "impulse_tol": 1e-2, "newton_tol": 1e-6, "rho_infinity": 0.3},
    "balanced": {"n_nodes": 64, "dt": 1e-2, "impulse_tol": 2e-3, "newton_tol": 1e-9, "rho_infinity": 0.3},
    "accurate": {"n_nodes": 128, "dt": 5e-3, "impulse_tol": 5e-4, "newton_tol": 1e-10, "rho_infinity": 0.3},
}


def with_fidelity(scene: Scene, fidelity: str) -> Scene:
    """``scene`` with the numerical settings of preset ``fidelity`` ("fast" | "balanced" | "accurate")."""
    check_choice("with_fidelity", "fidelity", fidelity, tuple(FIDELITY_PRESETS))
    if not isinstance(scene, Scene):
        raise ValueError(f"with_fidelity.scene = {scene!r} is invalid: must be a ballenv.physics.Scene")
    preset = FIDELITY_PRESETS[fidelity]
    rings = tuple(dataclasses.replace(r, n_nodes=preset["n_nodes"]) for r in scene.rings)
    return dataclasses.replace(
        scene,
        rings=rings,
        integrator="generalized_alpha",
        adaptive=True,
        dt=preset["dt"],
        impulse_tol=preset["impulse_tol"],
        newton_tol=preset["newton_tol"],
        rho_infinity=preset["rho_infinity"],
    )
