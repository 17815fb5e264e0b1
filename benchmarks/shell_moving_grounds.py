"""The 3-D ball on moving grounds against closed forms: a plate rising under it, a conveyor belt
under it, a table vibrating under it; with the wall time of each run.

    taskset -c 0 python benchmarks/shell_moving_grounds.py    # writes results/shell_moving_grounds.md

The default ball (``Shell()``, 162 vertices) is first settled on a fixed floor (backward Euler, 15
fixed steps of 10 ms), then, with ``Scene`` defaults but ``rtol = 1e-3``:

* a plate rising at u (m/s), the ball moving with it at t = 0: its centre's speed (a straight line
  fitted to its height from 0.05 s on) against u, and its energy gain over ``T_RISE`` against
  ``M g u T``;
* a belt at 1 m/s along x with friction mu, the ball at rest at t = 0: slip at ``mu g`` until its
  contact point moves with the belt, at ``t* = v / (mu g)`` with the centre speed
  ``v = u I / (I + M r^2)`` (I about the centre, r the centre's height); its centre speed when its
  contact point first reaches 0.99 u, and the mean speeds after ``1.5 t*``;
* a table vibrating at 5 Hz with peak acceleration Gamma g, the ball moving with it at t = 0: the
  first liftoff (the lowest vertex leaving the barrier's reach) against the phase
  ``asin(1 / Gamma) / omega`` at which a rigid ball leaves (none for Gamma < 1), and the largest
  energy above its start plus the credited work.

Wall time: ``Trajectory.stats.wall_time``, numba warm, one core.
"""

import math
import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import pathlib  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from ballenv.files import write_text  # noqa: E402
from ballenv.shell import Ground, Scene, Shell, equilibrium, simulate  # noqa: E402
from ballenv.shell.simulation import build  # noqa: E402
from ballenv.shell.skin.model import build_model  # noqa: E402
from ballenv.shell.step.implicit import total_energy  # noqa: E402

RESULTS = pathlib.Path(__file__).parent / "results"
G = 9.81
GAP = 0.87e-3  # m: the barrier's static gap under the ball's weight
RISE_SPEEDS = (0.2, 0.5, 1.0, 2.0)  # m/s
T_RISE = 0.2  # s
FRICTIONS = (0.3, 0.5, 1.0)
BELT = 1.0  # m/s
T_BELT = 0.4  # s
GAMMAS = (0.5, 0.9, 1.5, 3.0)
FREQUENCY = 5.0  # Hz
T_TABLE = 0.25  # s


def centre(mass, a):
    return np.einsum("...vk,v->...k", a, mass) / mass.sum()


def settled():
    """The default ball settled on a fixed floor: positions (V, 3) m, vertex masses (V,) kg."""
    x = equilibrium(Shell()).x
    mass = build_model(Shell()).mass
    lift = float((centre(mass, x) - x)[:, 2].max()) + GAP
    ball = Shell(position=(0, 0, lift))
    scene = Scene(shells=[ball], grounds=[Ground()], integrator="backward_euler", adaptive=False, dt=0.01)
    return simulate(scene, t_end=0.15).x[-1, 0], mass


def energy(scene, heights, x, v):
    st = build(scene)[1][0]
    st.heights[:] = heights
    return total_energy(st, x, v)


def rising(x0, mass, u):
    scene = Scene(grounds=[Ground(velocity=(0, 0, u))], rtol=1e-3)
    traj = simulate(scene, t_end=T_RISE, x0=x0[None], v0=np.tile([0.0, 0.0, u], (1, len(x0), 1)))
    z = centre(mass, traj.x[:, 0])[:, 2]
    late = traj.t >= 0.05
    speed = float(np.polyfit(traj.t[late], z[late], 1)[0])
    gain = energy(scene, u * T_RISE, traj.x[-1, 0], traj.v[-1, 0]) - energy(scene, 0.0, x0, traj.v[0, 0])
    lift = mass.sum() * G * u * T_RISE
    low = float((traj.x[:, 0, :, 2].min(axis=1) - u * traj.t).min())
    return (
        f"| {u:g} | {speed:.4f} | {100 * (speed / u - 1):+.2f} % | {gain:.4f} | {lift:.4f} | "
        f"{100 * (gain / lift - 1):+.2f} % | {traj.boundary_work[-1, 0]:.3f} | {low * 1e3:.3f} | "
        f"{traj.stats.steps} | {traj.stats.wall_time:.2f} |"
    )


def belt(x0, mass, mu):
    scene = Scene(grounds=[Ground(friction=mu, velocity=(BELT, 0, 0))], rtol=1e-3)
    traj = simulate(scene, t_end=T_BELT, x0=x0[None], output_dt=0.0025)
    c, vc = centre(mass, traj.x[:, 0]), centre(mass, traj.v[:, 0])
    r = x0 - centre(mass, x0)
    inertia = float(np.sum(mass * (r[:, 0] ** 2 + r[:, 2] ** 2)))
    rolling = BELT * inertia / (inertia + mass.sum() * float(c[0, 2]) ** 2)
    slip_end = rolling / (mu * G)
    about = np.cross(traj.x[:, 0] - c[:, None], traj.v[:, 0] - vc[:, None])[..., 1]
    contact_point = vc[:, 0] - about @ mass / inertia * c[:, 2]
    rolls = int(np.argmax(contact_point >= 0.99 * BELT))
    late = traj.t >= 1.5 * slip_end
    v_late, cp_late = float(np.mean(vc[late, 0])), float(np.mean(contact_point[late]))
    at_roll, late_error = vc[rolls, 0], 100 * (v_late / rolling - 1)
    return (
        f"| {mu:g} | {rolling:.4f} | {slip_end:.4f} | {traj.t[rolls]:.4f} | {at_roll:.4f} "
        f"({100 * (at_roll / rolling - 1):+.2f} %) | {v_late:.4f} ({late_error:+.2f} %) | "
        f"{cp_late:.4f} ({100 * (cp_late / BELT - 1):+.2f} %) | {traj.stats.steps} | "
        f"{traj.stats.wall_time:.2f} |"
    )


def table(x0, mass, gamma):
    omega = 2 * math.pi * FREQUENCY
    amplitude = gamma * G / omega**2
    scene = Scene(grounds=[Ground(amplitude=amplitude, frequency=FREQUENCY)], rtol=1e-3)
    v0 = np.tile([0.0, 0.0, amplitude * omega], (1, len(x0), 1))
    traj = simulate(scene, t_end=T_TABLE, x0=x0[None], v0=v0)
    liftoffs = [t for t, _, kind, _ in traj.events if kind == "liftoff"]
    rigid = f"{math.asin(1 / gamma) / omega:.4f}" if gamma > 1 else "none"
    first = f"{liftoffs[0]:.4f}" if liftoffs else "none"
    excess = max(
        energy(scene, amplitude * math.sin(omega * t), x, v) - w
        for t, x, v, w in zip(traj.t, traj.x[:, 0], traj.v[:, 0], traj.boundary_work[:, 0], strict=True)
    ) - energy(scene, 0.0, x0, v0[0])
    return (
        f"| {gamma:g} | {amplitude * 1e3:.3f} | {rigid} | {first} | {len(liftoffs)} | "
        f"{traj.boundary_work[-1, 0]:.4f} | {excess:.2e} | {traj.stats.steps} | {traj.stats.wall_time:.2f} |"
    )


def main() -> None:
    clock = time.perf_counter()
    x0, mass = settled()
    lines = [
        "# The 3-D ball on moving grounds",
        "",
        "`python benchmarks/shell_moving_grounds.py` (see its docstring), {minutes} on the shared 2-core "
        "machine.",
        "",
        "## A plate rising at u under the ball",
        "",
        "| u (m/s) | centre speed (m/s) | error | energy gain (J) | M g u T (J) | error | credited work (J) "
        "| lowest vertex above the plate (mm) | steps | wall (s) |",
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
        *[rising(x0, mass, u) for u in RISE_SPEEDS],
        "",
        f"## A conveyor belt at {BELT:g} m/s under the ball at rest",
        "",
        "| mu | u I / (I + M r^2) (m/s) | t* (s) | contact point at 0.99 u (s) | centre speed then (m/s) "
        "| mean centre speed after 1.5 t* | mean contact-point speed | steps | wall (s) |",
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
        *[belt(x0, mass, mu) for mu in FRICTIONS],
        "",
        f"## A table vibrating at {FREQUENCY:g} Hz with peak acceleration Gamma g",
        "",
        "| Gamma | A (mm) | rigid ball leaves (s) | first liftoff (s) | liftoffs | credited work (J) "
        "| largest E - E0 - W (J) | steps | wall (s) |",
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
        *[table(x0, mass, gamma) for gamma in GAMMAS],
        "",
    ]
    minutes = f"{(time.perf_counter() - clock) / 60:.1f} min"
    lines[2] = lines[2].format(minutes=minutes)
    write_text(RESULTS / "shell_moving_grounds.md", "\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
