"""The numerical settings behind InflatedBall-v3's ``fidelity`` keyword.

They are part of the env's dynamics and so belong to its version: a change here is a new env
version. (The simulator's presets, :mod:`ballenv.physics.presets`, are defined by a requested
accuracy and may be retuned without touching the env.) Each fidelity sets the ring's node count,
which is also the observation's, and the step control: generalized-alpha with
``rho_infinity = 0.3`` and the step adapted to the contact impulse (``Scene.adaptive``,
``Scene.impulse_tol``):

=========  ======  ===========  ============  ============
fidelity   nodes   largest dt   impulse_tol   newton_tol
=========  ======  ===========  ============  ============
fast       32      0.02 s       0.01 N s      1e-6
balanced   64      0.01 s       0.002 N s     1e-9
accurate   128     0.005 s      0.0005 N s    1e-10
=========  ======  ===========  ============  ============

What each costs per env step: ``benchmarks/env_throughput.py`` and ``benchmarks/env_profile.py``.
"""

from typing import Any

from ..physics.presets import with_numerics
from ..physics.scene import Scene

ENV_FIDELITIES: dict[str, dict[str, Any]] = {
    "fast": {"n_nodes": 32, "dt": 2e-2, "impulse_tol": 1e-2, "newton_tol": 1e-6},
    "balanced": {"n_nodes": 64, "dt": 1e-2, "impulse_tol": 2e-3, "newton_tol": 1e-9},
    "accurate": {"n_nodes": 128, "dt": 5e-3, "impulse_tol": 5e-4, "newton_tol": 1e-10},
}
ENV_RHO_INFINITY = 0.3  # generalized-alpha's high-frequency damping in every fidelity


def with_env_fidelity(scene: Scene, fidelity: str) -> Scene:
    """``scene`` with the env's numerical settings of ``fidelity`` (a key of :data:`ENV_FIDELITIES`)."""
    numerics = ENV_FIDELITIES[fidelity]
    return with_numerics(
        scene,
        numerics["n_nodes"],
        integrator="generalized_alpha",
        adaptive=True,
        rtol=0.0,
        dt=numerics["dt"],
        impulse_tol=numerics["impulse_tol"],
        newton_tol=numerics["newton_tol"],
        rho_infinity=ENV_RHO_INFINITY,
    )
