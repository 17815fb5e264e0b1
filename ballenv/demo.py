"""The README's demo: simulate an inflated ball and write a plot.

    python -m ballenv.demo --out out

An inflated ring (R = 0.1 m, E = 10 MPa, 30 kPa) released squashed into an ellipse falls under
gravity while it rings; the plot shows its shapes, the centre of mass against the analytic free fall
``y0 - g t^2 / 2`` and the energy balance of both integrators.
"""

import argparse
import pathlib

import numpy as np

from ballenv.physics import Ring, Scene, simulate


def run(out_dir, t_end=0.2):
    """Simulate the demo scene with both integrators, save ``demo.png``, return the trajectories."""
    ring = Ring(radius=0.1, n_nodes=64, pressure=30e3, position=(0.0, 1.0))
    theta = 2 * np.pi * np.arange(ring.n_nodes) / ring.n_nodes
    x0 = np.stack([0.115 * np.cos(theta), 1.0 + 0.085 * np.sin(theta)], axis=1)
    trajectories = {}
    for integrator in ("generalized_alpha", "backward_euler"):
        scene = Scene(rings=[ring], integrator=integrator, dt=1e-4)
        traj = simulate(scene, t_end, x0=x0, output_dt=1e-3, progress=True)
        trajectories[integrator] = traj
        s = traj.stats
        print(
            f"{integrator:18s} steps {s.steps:6d}  rejected {s.rejected_steps:3d}  Newton "
            f"{s.newton_iterations:6d}  wall {s.wall_time * 1e3:7.1f} ms  "
            f"({s.wall_time / s.steps * 1e6:.1f} us/step)  effects {', '.join(s.effects)}"
        )
    out = pathlib.Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    path = out / "demo.png"
    _plot(trajectories, path)
    print(f"wrote {path}")
    return trajectories


def _plot(trajectories, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.5))
    ga = trajectories["generalized_alpha"]
    for k in np.linspace(0, len(ga.t) - 1, 6).astype(int):
        x = ga.x[k, 0]
        closed = np.vstack([x, x[:1]])
        axes[0].plot(closed[:, 0], closed[:, 1], lw=1, label=f"t = {ga.t[k] * 1e3:.0f} ms")
    axes[0].set_aspect("equal")
    axes[0].set_xlabel("x (m)")
    axes[0].set_ylabel("y (m)")
    axes[0].set_title("shapes (generalized-alpha)")
    axes[0].legend(fontsize=7)
    for name, traj in trajectories.items():
        y = traj.centre_of_mass()[:, 0, 1]
        axes[1].plot(traj.t, y, label=name)
        e = traj.energy()["total"][:, 0]
        axes[2].plot(traj.t, e - e[0], label=name)
    axes[1].plot(ga.t, 1.0 - 0.5 * 9.81 * ga.t**2, "k:", label="y0 - g t^2/2")
    axes[1].set_xlabel("t (s)")
    axes[1].set_ylabel("centre of mass y (m)")
    axes[1].legend()
    axes[2].set_xlabel("t (s)")
    axes[2].set_ylabel("E(t) - E(0) (J): mechanical + gas")
    axes[2].set_title("energy balance (no damping: should be 0)")
    axes[2].legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out", help="folder for the plot (default: out)")
    parser.add_argument("--t-end", type=float, default=0.2, help="simulated time (s)")
    args = parser.parse_args(argv)
    run(args.out, args.t_end)


if __name__ == "__main__":
    main()
