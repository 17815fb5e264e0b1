"""Fidelity presets: named accuracy-for-cost settings of the numerical method.

Each preset sets the node count of every ring and the step control of the scene; the physics
(material, pressure, effects) is untouched. Their first-apex error and cost on a 1 m drop are
measured by ``benchmarks/env_throughput.py`` and listed in the README (fast 3.1 %, balanced 0.14 %,
accurate 0.04 %); choosing them from a work-precision study is issue 7:

=========  ======  ==================  ===========  ================  ============
preset     nodes   integrator          largest dt   impulse_tol       newton_tol
=========  ======  ==================  ===========  ================  ============
fast       32      generalized-alpha   0.02 s       0.01 N s          1e-6
balanced   64      generalized-alpha   0.01 s       0.002 N s         1e-9
accurate   128     generalized-alpha   0.005 s      0.0005 N s        1e-10
=========  ======  ==================  ===========  ================  ============

All adapt the step to the contact impulse (``Scene.adaptive``).
"""

import dataclasses

from .scene import Scene, check_choice

FIDELITY_PRESETS = {
    "fast": {"n_nodes": 32, "dt": 2e-2, "impulse_tol": 1e-2, "newton_tol": 1e-6},
    "balanced": {"n_nodes": 64, "dt": 1e-2, "impulse_tol": 2e-3, "newton_tol": 1e-9},
    "accurate": {"n_nodes": 128, "dt": 5e-3, "impulse_tol": 5e-4, "newton_tol": 1e-10},
}


def with_fidelity(scene, fidelity):
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
    )
