"""Fidelity presets of the 3-D ball: named accuracy-for-cost settings of the numerical method, each
defined by the accuracy it asks for.

Each preset sets every shell's mesh (``Shell.subdivisions``) and the scene's step control; the
physics (material, pressure, gas, effects, grounds) is untouched. All are generalized-alpha with
``rho_infinity = 0`` (the skin's modes above what the step resolves are damped within a step
instead of ringing on, which would cost steps and Newton iterations; the work-precision page
shows it the cheapest for a given first-apex error) with adaptive steps at most ``dt``:

=========  ========  ======  =====  ==========  ===========  ===========================
preset     vertices  k       rtol   largest dt  newton_tol   first-apex error (bound)
=========  ========  ======  =====  ==========  ===========  ===========================
fast       162       2       1e-3   0.01 s      1e-4         2.5 %
balanced   642       3       3e-4   0.004 s     1e-6         0.75 %
accurate   2562      4       1e-4   0.002 s     1e-7         0.5 %
=========  ========  ======  =====  ==========  ===========  ===========================

The bound is on the error of the step control: the first apex of each ball of
``benchmarks/shell_presets.py`` against a converged run of the same ball on the same mesh
(``tests/shell/test_presets.py`` checks it; ``benchmarks/results/shell_presets.md`` has the
errors and wall times), the worst of each run and of runs with ``rtol`` a few per cent off. A
loosely converged run (the fast preset's Newton tolerance) moves with such a change as with the
rounding of another CPU (one Newton iteration more or less in a contact step), and its bound
covers that spread. The mesh is a separate choice with its own
error, which the same page gives for every ball against the finest mesh.
"""

import dataclasses
from typing import Any

from ..physics.scene import check_choice
from .scene import Scene

PRESET_RHO_INFINITY = 0.0

FIDELITY_PRESETS: dict[str, dict[str, Any]] = {
    "fast": {"subdivisions": 2, "rtol": 1e-3, "dt": 1e-2, "newton_tol": 1e-4, "apex_error_bound": 0.025},
    "balanced": {"subdivisions": 3, "rtol": 3e-4, "dt": 4e-3, "newton_tol": 1e-6, "apex_error_bound": 0.0075},
    "accurate": {"subdivisions": 4, "rtol": 1e-4, "dt": 2e-3, "newton_tol": 1e-7, "apex_error_bound": 0.005},
}


def with_fidelity(scene: Scene, fidelity: str) -> Scene:
    """``scene`` with the mesh and step control of preset ``fidelity`` ("fast" | "balanced" |
    "accurate")."""
    check_choice("with_fidelity", "fidelity", fidelity, tuple(FIDELITY_PRESETS))
    if not isinstance(scene, Scene):
        raise ValueError(f"with_fidelity.scene = {scene!r} is invalid: must be a ballenv.shell.Scene")
    preset = FIDELITY_PRESETS[fidelity]
    shells = tuple(dataclasses.replace(s, subdivisions=preset["subdivisions"]) for s in scene.shells)
    return dataclasses.replace(
        scene,
        shells=shells,
        integrator="generalized_alpha",
        rho_infinity=PRESET_RHO_INFINITY,
        adaptive=True,
        rtol=preset["rtol"],
        dt=preset["dt"],
        dt_min=min(scene.dt_min, preset["dt"]),
        newton_tol=preset["newton_tol"],
    )
