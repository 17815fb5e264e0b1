"""The README's demo: drop an inflated ball on the ground and plot its bounces.

    python -m ballenv.demo --out out

An inflated ring (R = 0.1 m, N = 64, E = 10 MPa, h = 2 mm) is dropped from 1 m onto flat ground at
three inflation pressures (generalized-alpha, mass-modification contact, adaptive step). The plot
shows the shapes through the first impact, the centre-of-mass height with the apexes located inside
the step (the paper's figure 6 trend: higher pressure, higher bounce), and the adaptive step size
against the ground reaction (large steps in flight, small ones in contact).
"""

import argparse
import pathlib

import numpy as np

from ballenv.physics import Ground, Ring, Scene, simulate

PRESSURES = (10e3, 30e3, 60e3)  # Pa


def demo_scene(pressure):
    """The demo's scene at one inflation pressure (Pa)."""
    ring = Ring(
        radius=0.1, n_nodes=64, youngs_modulus=10e6, thickness=2e-3, pressure=pressure, position=(0.0, 1.0)
    )
    return Scene(rings=[ring], grounds=[Ground()], adaptive=True, dt=1e-2, impulse_tol=1e-3)


def run(out_dir, t_end=1.5):
    """Simulate the demo scenes, save ``demo.png``, return the trajectories by pressure."""
    trajectories = {}
    for pressure in PRESSURES:
        traj = simulate(demo_scene(pressure), t_end, progress=True)
        trajectories[pressure] = traj
        s = traj.stats
        apexes = ", ".join(f"{h:.3f}" for h in traj.apexes()[:, 1])
        print(
            f"p = {pressure / 1e3:4.0f} kPa: apexes {apexes} m | steps {s.steps} (+{s.rejected_steps} "
            f"rejected), Newton {s.newton_iterations}, wall {s.wall_time * 1e3:.0f} ms | "
            f"effects {', '.join(s.effects)}"
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

    fig, axes = plt.subplots(1, 3, figsize=(16, 4.6))
    traj = trajectories[PRESSURES[0]]
    touch = next(t for t, _, kind in traj.events if kind == "touchdown")
    lift = next(t for t, _, kind in traj.events if kind == "liftoff")
    for t in np.linspace(touch - 0.01, lift + 0.01, 6):
        k = int(np.argmin(np.abs(traj.t - t)))
        closed = np.vstack([traj.x[k, 0], traj.x[k, 0, :1]])
        axes[0].plot(closed[:, 0], closed[:, 1], lw=1, label=f"t = {traj.t[k] * 1e3:.1f} ms")
    axes[0].axhline(0.0, color="k", lw=1.5)
    axes[0].set_aspect("equal")
    axes[0].set_ylim(-0.01, 0.25)
    axes[0].set_xlabel("x (m)")
    axes[0].set_ylabel("y (m)")
    axes[0].set_title(f"first impact at {PRESSURES[0] / 1e3:.0f} kPa")
    axes[0].legend(fontsize=7)
    for pressure, tr in trajectories.items():
        line = axes[1].plot(tr.t, tr.centre_of_mass()[:, 0, 1], lw=1, label=f"{pressure / 1e3:.0f} kPa")
        apex = tr.apexes()
        axes[1].plot(apex[:, 0], apex[:, 1], "o", ms=4, color=line[0].get_color())
    axes[1].set_xlabel("t (s)")
    axes[1].set_ylabel("centre height (m)")
    axes[1].set_title("bounces (dots: apexes located inside the step)")
    axes[1].legend()
    tr = trajectories[PRESSURES[1]]
    axes[2].semilogy(tr.t[1:], np.diff(tr.t), lw=0.8)
    axes[2].set_xlabel("t (s)")
    axes[2].set_ylabel("adaptive step (s)")
    twin = axes[2].twinx()
    twin.plot(tr.t, tr.contact_force[:, 0, :, 1].sum(axis=1), color="tab:red", lw=0.8)
    twin.set_ylabel("ground reaction (N)", color="tab:red")
    axes[2].set_title(f"step size and contact force at {PRESSURES[1] / 1e3:.0f} kPa")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out", help="folder for the plot (default: out)")
    parser.add_argument("--t-end", type=float, default=1.5, help="simulated time (s)")
    args = parser.parse_args(argv)
    run(args.out, args.t_end)


if __name__ == "__main__":
    main()
