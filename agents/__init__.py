"""Agents for InflatedBall-v3: baseline policies, per-algorithm hyperparameters, evaluation.

* ``agents.baselines``: random actions and the scripted heuristics of ``ballenv.controllers``
  (pressure pumping, paddle dribbling), and a saved Stable-Baselines3 model, behind one interface.
* ``agents/hyperparams/{ppo,sac}.yml``: hyperparameters in the RL Baselines3 Zoo format, one entry
  per env id (one id per action mode), read by ``agents.train``.
* ``agents.evaluate``: the score of any of them on held-out seeds (``ballenv-evaluate``);
  ``agents.evaluate3d``: the 3-D ball's (InflatedBall3D-v0), its apexes' height and spot errors.
* ``agents.train``: training and scoring (``python train.py``, ``ballenv-train``).
"""
