"""How much a bounce depends on where the ring's nodes sit when it lands, per fidelity preset.

    python benchmarks/bounce_phase.py        # writes benchmarks/results/bounce_phase.md

The env's ball (``BallEnvConfig().scene()`` of each preset: R = 0.12 m, 30 kPa, friction 0.5,
damping 20 1/s, generalized-alpha with ``rho_infinity`` = 0.3, impulse-adaptive steps) lands on
flat ground in two ways: dropped from rest at 1 m, and thrown down at 2 m/s from 0.8 m (a ball
the paddle has struck). The same ball is turned by ``phase`` times the angle between two nodes,
``2 pi / N``, before it is released, for ``PHASES`` phases in [0, 1/2] (a ring of N equal nodes
is mirror-symmetric, so phase ``q`` and ``1 - q`` land alike). A smooth ball's bounce does not
depend on that angle; a polygon's does. Reported: the rise ``a - R`` of the first apex ``a`` after
the bounce (m), its mean over the phases, standard deviation and range relative to the mean. The
paddle's scripted controller assumes a bounce keeps a fixed fraction of the ball's energy; the
spread is what no controller that sees the ball as a body can predict.
"""

import dataclasses
import math
import os
import pathlib

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from ballenv.envs.config import BallEnvConfig  # noqa: E402
from ballenv.envs.numerics import ENV_FIDELITIES  # noqa: E402
from ballenv.files import write_text  # noqa: E402
from ballenv.physics import simulate  # noqa: E402
from ballenv.physics.base.ring import initial_nodes  # noqa: E402

RESULTS = pathlib.Path(__file__).parent / "results"
PHASES = 9  # rotations 0, 1/16, ..., 1/2 of the angle between two nodes
LAUNCHES = {  # name -> (centre height m, vertical velocity m/s)
    "dropped from 1 m": (1.0, 0.0),
    "thrown down at 2 m/s from 0.8 m": (0.8, -2.0),
}
T_END = 1.0  # s: past the first apex after the bounce


def rises(fidelity: str, height: float, velocity: float) -> np.ndarray:
    """The first apex's rise above the ring's rest radius (m) after the bounce, one per phase."""
    config = BallEnvConfig(fidelity=fidelity)
    scene = config.scene()
    ring = dataclasses.replace(scene.rings[0], position=(0.0, height), velocity=(0.0, velocity))
    scene = dataclasses.replace(scene, rings=[ring])
    x, v = (np.asarray(a).reshape(-1, 2) for a in initial_nodes(ring))
    centre = np.array(ring.position)
    out = np.empty(PHASES)
    for k in range(PHASES):
        angle = 2.0 * math.pi / ring.n_nodes * 0.5 * k / (PHASES - 1)
        turn = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
        nodes = (x - centre) @ turn.T + centre
        traj = simulate(scene, T_END, x0=nodes[None], v0=v[None])
        apexes = traj.apexes()
        out[k] = apexes[0, 1] - ring.radius if len(apexes) else math.nan
    return out


def main() -> None:
    rows = [
        "| preset | N | launch | rise mean (m) | std / mean | (max - min) / mean |",
        "|---|---:|---|---:|---:|---:|",
    ]
    for fidelity, preset in ENV_FIDELITIES.items():
        for launch, (height, velocity) in LAUNCHES.items():
            r = rises(fidelity, height, velocity)
            spread = (r.max() - r.min()) / r.mean()
            rows.append(
                f"| {fidelity} | {preset['n_nodes']} | {launch} | {r.mean():.4f} | "
                f"{100 * r.std() / r.mean():.2f} % | {100 * spread:.1f} % |"
            )
            print(rows[-1], flush=True)
    text = (
        "# The bounce against the ring's rotation at landing\n\n"
        f"`python benchmarks/bounce_phase.py`: the env's ball turned by {PHASES} phases in [0, 1/2] "
        "of the angle between two nodes before release; the rise of the first apex after the bounce.\n\n"
        + "\n".join(rows)
        + "\n"
    )
    RESULTS.mkdir(exist_ok=True)
    write_text(RESULTS / "bounce_phase.md", text)
    print(f"wrote {RESULTS / 'bounce_phase.md'}")


if __name__ == "__main__":
    main()
