"""The README's main job: train a Stable-Baselines3 agent on InflatedBall-v3 and score it.

    python train.py --algo ppo --action-mode pressure    # = make train (which adds --vec-env subproc)

The same command is installed as ``ballenv-train``; everything lives in :mod:`agents.train`.
"""

from agents.train import main

if __name__ == "__main__":
    main()
