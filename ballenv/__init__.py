"""ballenv: an inflated elastic ball (a 2-D ring of discrete elastic rods) as an RL environment."""

__version__ = "0.1.0"
