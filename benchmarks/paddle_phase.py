"""Whether the paddle mode's bounce scatter is predictable from where the ring's nodes will land.

    python benchmarks/paddle_phase.py [--episodes 200]   # writes benchmarks/results/paddle_phase.md

The env is InflatedBallPaddle-v3 (fast preset, N = 32), played by the tuned scripted
``PaddleDribble`` on training seeds 0, 1, ... Each strike is followed by one bounce; its outcome is
the signed relative error ``e = (h - h_target) / h_target`` of the next flight apex, which the
controller's energy balance aims at 0 assuming a fixed retention. A 32-gon's bounce depends on its
rotation at the touch (``benchmarks/bounce_phase.py``: 3.0-3.5 % of the rise over half a node
spacing). That rotation is in the observation: the nodes' positions and velocities relative to the
centre of mass give the ring's angle and spin, and the centre's height and velocity the time to
the touch, so the **landing rotation phase** ``q`` in node spacings
(``agents.wrappers.rotation_phase``) is known at the strike.

Reported: the scatter (standard deviation) of ``e`` and what out-of-sample fits (five-fold) leave
of it: least squares on what the controller sees (centre height and velocity after the strike,
the apex it saw, target, impulse), the same with the landing phase's first three harmonics
(``cos 2 pi k q``, ``sin 2 pi k q``; from the observation after the strike, and predicted before
it, what a policy deciding the strike can know: the strike's push on the centre counted, the spin
it gives the ring not), and a 64-64 network (``pump_response.network_residual_sd``) on either and
on all a policy knows before the strike, with the ring's rotation phase and spin then (which nodes
the paddle meets sets the spin it gives).
"""

import argparse
import math
import os
import pathlib
import sys

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import gymnasium as gym  # noqa: E402
from pump_response import FOLDS, network_residual_sd  # noqa: E402

import ballenv  # noqa: E402, F401  (registers the env)
from agents.baselines import HeuristicPolicy  # noqa: E402
from agents.wrappers import phase_harmonics, ring_angle, ring_spin, rotation_phase  # noqa: E402
from ballenv.envs import ENV_IDS  # noqa: E402
from ballenv.files import write_text  # noqa: E402
from ballenv.physics.base.ring import total_mass  # noqa: E402

RESULT = ROOT / "benchmarks" / "results" / "paddle_phase.md"
BODY = ("height", "vertical velocity", "apex seen", "target", "impulse")


COLUMNS = (*BODY, "phase after", "phase before", "phase now", "spin", "error")


def strikes(episodes, seed=0):
    """Per strike, the columns ``COLUMNS``: the body's numbers (``BODY``, after the strike), the
    landing phase from the observation after the strike, the one predicted before it (the
    strike's push ``J / m`` on the centre counted, not the spin it gives), the ring's rotation
    phase and spin (rad/s) at the strike, and the next apex's signed relative error, over
    ``episodes`` episodes of the tuned ``PaddleDribble``; a dict of column -> array."""
    env = gym.make(ENV_IDS["paddle"])
    ball = env.unwrapped
    structure, config = ball.observation_structure, ball.config
    g, mass = config.gravity, total_mass(config.ring(config.initial_pressure))
    policy = HeuristicPolicy(env)
    rows = []
    for episode in range(episodes):
        obs, _ = env.reset(seed=seed + episode)
        policy.reset(seed + episode)
        pending = None
        while True:
            action = policy.act(obs)
            push = 0.5 * (float(action[0]) + 1.0) * config.paddle_max_impulse / mass
            nodes = obs[structure["node_position"]].reshape(-1, 2).astype(np.float64)
            decision = [
                rotation_phase(obs, structure, g, push),
                (len(nodes) * ring_angle(nodes) / (2.0 * math.pi)) % 1.0,
                ring_spin(obs, structure),
            ]
            obs, _, terminated, truncated, info = env.step(action)
            if info["apex_count"] and pending is not None:
                target = info["target_height"]
                rows.append(pending + [(info["apex_height"] - target) / target])
                pending = None
            impulse = float(obs[structure["paddle_impulse"]][0])
            if impulse > 0.0:
                y = float(obs[structure["centre_of_mass_position"]][1])
                vy = float(obs[structure["centre_of_mass_velocity"]][1])
                seen = policy.controller.apex
                target = float(obs[structure["target_height"]][0])
                pending = [y, vy, seen, target, impulse, rotation_phase(obs, structure, g), *decision]
            if terminated or truncated:
                break
    env.close()
    return dict(zip(COLUMNS, np.array(rows).T, strict=True))


def linear_residual_sd(y, x):
    """Standard deviation of ``y`` left out of sample by least squares on ``x`` (and a constant),
    over the same ``FOLDS`` random parts as :func:`pump_response.network_residual_sd`."""
    parts = np.array_split(np.random.default_rng(0).permutation(len(y)), FOLDS)
    design = np.column_stack([np.ones(len(y)), x])
    predicted = np.empty(len(y))
    for k, part in enumerate(parts):
        rest = np.concatenate([p for j, p in enumerate(parts) if j != k])
        coef, *_ = np.linalg.lstsq(design[rest], y[rest], rcond=None)
        predicted[part] = design[part] @ coef
    return float(np.std(y - predicted))


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--episodes", type=int, default=200)
    args = p.parse_args()
    data = strikes(args.episodes)
    body, error = np.column_stack([data[name] for name in BODY]), data["error"]
    after, before = phase_harmonics(data["phase after"]), phase_harmonics(data["phase before"])
    decided = np.column_stack([body, before, phase_harmonics(data["phase now"]), data["spin"]])
    body_after, body_before = np.column_stack([body, after]), np.column_stack([body, before])
    rows = [
        ("none (the scatter itself)", float(error.std())),
        ("least squares on the body", linear_residual_sd(error, body)),
        ("least squares on the landing phase's harmonics", linear_residual_sd(error, after)),
        ("least squares on the body and the landing phase", linear_residual_sd(error, body_after)),
        ("network on the body", network_residual_sd(error, body)),
        ("network on the body and the landing phase", network_residual_sd(error, body_after)),
        ("least squares on the body and the landing phase predicted before the strike",
         linear_residual_sd(error, body_before)),
        ("network on the body and the landing phase predicted before the strike",
         network_residual_sd(error, body_before)),
        ("network on what is known before the strike: the body, that phase, the rotation phase "
         "and spin at the strike", network_residual_sd(error, decided)),
    ]  # fmt: skip
    lines = [
        "# The paddle's bounce against the landing rotation phase",
        "",
        f"`python benchmarks/paddle_phase.py --episodes {args.episodes}`: {len(error)} strikes of the "
        "tuned `PaddleDribble` on InflatedBallPaddle-v3 (N = 32), each followed by one bounce; the "
        "next apex's signed relative error `e` and what out-of-sample fits (five-fold) leave of it.",
        "",
        "| fit of e on | scatter of e left (std) |",
        "|---|---:|",
    ]
    for name, left in rows:
        lines.append(f"| {name} | {left:.4f} |")
        print(lines[-1], flush=True)
    RESULT.parent.mkdir(exist_ok=True)
    write_text(RESULT, "\n".join(lines) + "\n")
    print(f"wrote {RESULT}")


if __name__ == "__main__":
    main()
