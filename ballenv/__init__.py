"""ballenv: an inflated elastic ball (a 2-D ring of discrete elastic rods) as an RL environment.

Importing the package registers ``InflatedBall-v0`` with Gymnasium (Gymnasium 1.x has no plugin
entry point): ``import ballenv; gym.make("InflatedBall-v0")``, or, without the import (e.g. in
spawned subprocesses), ``gym.make("ballenv:InflatedBall-v0")``.
"""

from .envs import register_envs

__version__ = "0.1.0"

register_envs()
