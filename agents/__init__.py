"""Agents for InflatedBall-v1: baseline policies, per-algorithm hyperparameters, evaluation.

* ``agents.baselines``: random actions and the scripted heuristics of ``ballenv.controllers``
  (pressure pumping, paddle dribbling), and a saved Stable-Baselines3 model, behind one interface.
* ``agents/hyperparams/{ppo,sac}.yml``: hyperparameters keyed by env id and action mode
  (RL Baselines3 Zoo style), read by ``train.py``.
* ``agents.evaluate``: the score of any of them on held-out seeds (``python -m agents.evaluate``).
"""
