"""InflatedBall3D-v0 and InflatedBall3DPaddle-v0: the 3-D ball (``ballenv.shell``) as a Gymnasium
environment. The keywords and what derives from them (config.py), the observation's layout
(observation.py), the task's rules (task.py), one env's ball and task state (ball.py) and the env
(env.py)."""
