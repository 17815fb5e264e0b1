"""The 3-D shell's cost in simulated time: a drop from 0.5 m and three bounces of the default ball
(``Shell()``: R = 0.12 m, E = 5 MPa, nu = 0.45, h = 3 mm, rho = 1100 kg/m^3, p = 55 kPa, isothermal
gas) on a flat ground with friction 0.5, ``Scene`` defaults otherwise (generalized-alpha, rho_inf =
0.9, adaptive steps with rtol = 1e-4, no damping), on icospheres of 162 and 642 vertices.

    taskset -c 0 python benchmarks/shell_drop.py     # writes benchmarks/results/shell_drop.md

The run starts with the centre at 0.5 m, at rest, and ends at the touchdown after the third apex
(the drop and three bounces; a contact may count more than one touchdown, where the lowest
vertices leave the barrier's reach for a moment). Wall time is ``simulate``'s stepping
(``Trajectory.stats.wall_time``, pro rata of the steps up to that touchdown), numba warm (a short
run first), on one core (OPENBLAS_NUM_THREADS=1; the script pinned by taskset), on a 2-core
machine shared with other jobs (the same run varies by up to 2x). Targets: 162 vertices at >= 10x
real time, 642 at >= 1x.
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import pathlib  # noqa: E402
import sys  # noqa: E402

from ballenv.files import write_text  # noqa: E402
from ballenv.shell import Ground, Scene, Shell, simulate  # noqa: E402

RESULTS = pathlib.Path(__file__).parent / "results"
DROP = 0.5  # m: the centre's start height
BOUNCES = 3
TARGETS = {2: 10.0, 3: 1.0}  # subdivisions -> the real-time factor asked for


def run(subdivisions: int) -> dict:
    """The drop of the ``subdivisions`` ball up to the touchdown after its third apex."""
    ball = Shell(subdivisions=subdivisions, position=(0.0, 0.0, DROP))
    scene = Scene(shells=[ball], grounds=[Ground(friction=0.5)])
    simulate(scene, t_end=0.01)  # compile
    t_end = 2.4
    traj = simulate(scene, t_end=t_end)
    apexes = traj.apexes()
    last_apex = apexes[BOUNCES - 1, 0] if len(apexes) >= BOUNCES else t_end
    after = [t for t, _, kind, _ in traj.events if kind == "touchdown" and t > last_apex]
    simulated = after[0] if after else t_end
    share = sum(1 for t in traj.t[1:] if t <= simulated) / max(len(traj.t) - 1, 1)
    s = traj.stats
    wall = s.wall_time * share  # the stepping's time up to the last touchdown (steps pro rata)
    return {
        "vertices": ball.n_vertices,
        "simulated": simulated,
        "wall": wall,
        "real_time": simulated / wall,
        "target": TARGETS[subdivisions],
        "apex": apexes[0, 1] if len(apexes) else float("nan"),
        "apexes": ", ".join(f"{z:.4f}" for z in apexes[:BOUNCES, 1]),
        "touchdowns": sum(1 for t, _, kind, _ in traj.events if kind == "touchdown" and t <= simulated),
        "steps": round(s.steps * share),
        "rejections": s.rejections,
        "newton": round(s.newton_iterations * share),
        "cg": round(s.cg_iterations * share),
        "envelope": s.envelope_solves,
    }


def table(rows: list[dict]) -> str:
    head = (
        "| vertices | simulated (s) | wall (s) | wall per simulated s | x real time | target "
        "| ratio to target | first apex (m) | apexes (m) | touchdowns | steps | rejected | Newton iterations "
        "| per step | CG iterations | envelope solves |\n"
        "|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|\n"
    )
    body = "".join(
        f"| {r['vertices']} | {r['simulated']:.3f} | {r['wall']:.1f} "
        f"| {r['wall'] / r['simulated']:.1f} "
        f"| {r['real_time']:.3f} | {r['target']:g} | {r['real_time'] / r['target']:.4f} | {r['apex']:.4f} "
        f"| {r['apexes']} | {r['touchdowns']} | {r['steps']} | {r['rejections']} | {r['newton']} "
        f"| {r['newton'] / r['steps']:.2f} "
        f"| {r['cg']} | {r['envelope']} |\n"
        for r in rows
    )
    return head + body


def main() -> None:
    rows = [run(k) for k in (2, 3)]
    text = (
        "# The 3-D shell: a drop and three bounces\n\n"
        f"`python {pathlib.Path(__file__).relative_to(pathlib.Path(__file__).parents[1])}` "
        "(see its docstring): the default ball dropped from a centre height of 0.5 m, simulated to "
        "the touchdown after its third apex.\n\n" + table(rows) + "\n"
        "Real time is simulated seconds per wall-clock second; the ratio to target is that over the "
        "target (>= 1 meets it). The apexes are the centre of mass's heights, located inside the steps.\n"
    )
    write_text(RESULTS / "shell_drop.md", text)
    sys.stdout.write(text)


if __name__ == "__main__":
    main()
