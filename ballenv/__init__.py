"""ballenv: an inflated elastic ball (a 2-D ring of discrete elastic rods) as an RL environment.

Importing the package registers ``InflatedBall-v3`` with Gymnasium (Gymnasium 1.x has no plugin
entry point): ``import ballenv; gym.make("InflatedBall-v3")``, or, without the import (e.g. in
spawned subprocesses), ``gym.make("ballenv:InflatedBall-v3")``. Without gymnasium installed the
simulator, ``ballenv.physics``, still imports (it needs only numpy, numba and tqdm).
"""

__version__ = "0.1.0"  # the package metadata reads it (pyproject.toml: dynamic version)

try:
    import gymnasium  # noqa: F401
except ModuleNotFoundError as missing:  # the simulator alone (ballenv.physics) needs no gymnasium
    if missing.name != "gymnasium":
        raise
else:
    from .envs import register_envs

    register_envs()
