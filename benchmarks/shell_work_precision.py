"""The 3-D shell's work-precision: the first apex's error against wall time over the integrators,
their tolerances and the meshes, and the first apex under mesh refinement.

    taskset -c 0 python benchmarks/shell_work_precision.py   # writes results/shell_work_precision.md

The scene is ``benchmarks/shell_drop.py``'s: the default ball (``Shell()``) dropped from a centre
height of 0.5 m onto a flat ground with friction 0.5, simulated to 0.65 s (after its first apex,
at about 0.56 s). For each mesh (162, 642 and 2562 vertices) a reference run (generalized-alpha,
rho_inf = 0.9, ``REFERENCE_RTOL``; on 2562 vertices ``REFERENCE_RTOL_FINEST``, its cost) gives
the first apex; the reference's own uncertainty is its change when its tolerance is tripled. Each
method (generalized-alpha at rho_inf = 0.9, 0.3 and 0, backward Euler) at each ``rtol`` is then
timed on that mesh (``Trajectory.stats.wall_time``, numba warm, one core) and its first apex
compared with the reference of the same mesh: the error of the time stepping. The mesh's own
error is the second table: the references' first apexes against the finest mesh's.
"""

import argparse
import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import pathlib  # noqa: E402
import time  # noqa: E402

from ballenv.files import write_bytes, write_text  # noqa: E402
from ballenv.shell import Ground, Scene, Shell, simulate  # noqa: E402

RESULTS = pathlib.Path(__file__).parent / "results"
DROP = 0.5  # m
T_END = 0.65  # s
REFERENCE_RTOL = 1e-6
REFERENCE_RTOL_FINEST = 1e-5
METHODS = (
    ("GA 0.9", "generalized_alpha", 0.9),
    ("GA 0.3", "generalized_alpha", 0.3),
    ("GA 0", "generalized_alpha", 0.0),
    ("BE", "backward_euler", 0.0),
)
RTOLS = {2: (3e-3, 1e-3, 3e-4, 1e-4), 3: (3e-3, 1e-3, 3e-4, 1e-4), 4: (3e-3, 1e-3)}
FINEST_METHODS = ("GA 0.3", "GA 0")  # on 2562 vertices (its cost)


def scene_of(subdivisions: int, integrator: str, rho_infinity: float, rtol: float) -> Scene:
    """The drop on the ``subdivisions`` icosphere with the given method."""
    ball = Shell(subdivisions=subdivisions, position=(0.0, 0.0, DROP))
    return Scene(
        shells=[ball],
        grounds=[Ground(friction=0.5)],
        integrator=integrator,
        rho_infinity=rho_infinity,
        rtol=rtol,
    )


def first_apex(scene: Scene) -> tuple[float, dict]:
    """The first apex's height (m) and the run's work."""
    traj = simulate(scene, t_end=T_END, output_dt=0.01)  # the apex is located in its step
    s = traj.stats
    apexes = traj.apexes()
    height = float(apexes[0, 1]) if len(apexes) else float("nan")
    work = {"steps": s.steps, "rejected": s.rejections, "newton": s.newton_iterations, "wall": s.wall_time}
    return height, work


def warm(subdivisions: int) -> None:
    """Compiles what a drop runs, contact included."""
    ball = Shell(subdivisions=subdivisions, position=(0.0, 0.0, 0.135), velocity=(0.0, 0.0, -1.0))
    simulate(Scene(shells=[ball], grounds=[Ground(friction=0.5)]), t_end=0.005)


def references(subdivisions: int) -> dict:
    """The reference's first apex (m), its change when its tolerance is tripled, and its work."""
    rtol = REFERENCE_RTOL_FINEST if subdivisions == 4 else REFERENCE_RTOL
    apex, work = first_apex(scene_of(subdivisions, "generalized_alpha", 0.9, rtol))
    coarser, _ = first_apex(scene_of(subdivisions, "generalized_alpha", 0.9, 3.0 * rtol))
    return {"rtol": rtol, "apex": apex, "uncertainty": abs(coarser - apex) / apex, **work}


def sweep(subdivisions: int, reference: float) -> list[dict]:
    """Every method at every tolerance on one mesh."""
    rows = []
    for label, integrator, rho in METHODS:
        if subdivisions == 4 and label not in FINEST_METHODS:
            continue
        for rtol in RTOLS[subdivisions]:
            apex, work = first_apex(scene_of(subdivisions, integrator, rho, rtol))
            rows.append(
                {"method": label, "rtol": rtol, "apex": apex, "error": apex / reference - 1.0, **work}
            )
    return rows


def method_table(vertices: int, rows: list[dict]) -> str:
    head = (
        f"\n## {vertices} vertices\n\n| method | rtol | steps | rejected | Newton | wall (s) | x real time "
        "| first apex (m) | first-apex error |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|\n"
    )
    return head + "".join(
        f"| {r['method']} | {r['rtol']:g} | {r['steps']} | {r['rejected']} | {r['newton']} | {r['wall']:.2f} "
        f"| {T_END / r['wall']:.3f} | {r['apex']:.5f} | {100 * r['error']:+.2f} % |\n"
        for r in rows
    )


def mesh_table(refs: dict[int, dict]) -> str:
    finest = refs[max(refs)]["apex"]
    head = (
        "\n## The first apex under mesh refinement\n\n| vertices | reference rtol | steps | wall (s) "
        "| first apex (m) | tripled rtol changes it by | against the finest mesh |\n"
        "|---:|---:|---:|---:|---:|---:|---:|\n"
    )
    return head + "".join(
        f"| {10 * 4**k + 2} | {r['rtol']:g} | {r['steps']} | {r['wall']:.1f} | {r['apex']:.5f} "
        f"| {100 * r['uncertainty']:.3f} % | {100 * (r['apex'] / finest - 1.0):+.2f} % |\n"
        for k, r in sorted(refs.items())
    )


def plot(sweeps: dict[int, list[dict]]) -> bytes | None:
    """Error against wall time per mesh and method (PNG), or None without matplotlib."""
    try:
        import io

        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return None
    fig, ax = plt.subplots(figsize=(7, 4.5))
    markers = {2: "o", 3: "s", 4: "^"}
    for k, rows in sweeps.items():
        for label, _, _ in METHODS:
            pts = [(r["wall"], max(abs(r["error"]), 1e-6)) for r in rows if r["method"] == label]
            if pts:
                ax.loglog(*zip(*pts, strict=True), marker=markers[k], label=f"{10 * 4**k + 2} v, {label}")
    ax.axhline(0.01, color="grey", lw=0.8, ls="--")
    ax.set_xlabel("wall time to 0.65 s (s, one core)")
    ax.set_ylabel("|first-apex error| against the same mesh's reference")
    ax.legend(fontsize=7, ncol=2)
    buf = io.BytesIO()
    fig.tight_layout()
    fig.savefig(buf, format="png", dpi=110)
    return buf.getvalue()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--meshes", type=int, nargs="+", default=[2, 3, 4], help="icosphere subdivisions")
    args = parser.parse_args()
    clock = time.perf_counter()
    refs, sweeps = {}, {}
    for k in args.meshes:
        warm(k)
        refs[k] = references(k)
        sweeps[k] = sweep(k, refs[k]["apex"])
        print(f"{10 * 4**k + 2} vertices done at {time.perf_counter() - clock:.0f} s", flush=True)
    minutes = (time.perf_counter() - clock) / 60.0
    text = (
        "# The 3-D ball's work-precision\n\n"
        f"`python benchmarks/shell_work_precision.py` (see its docstring), {minutes:.0f} min on the "
        "shared 2-core machine. GA = generalized-alpha at the given rho_inf, BE = backward Euler; "
        "x real time = 0.65 s simulated over the wall time. The error is the first apex's height "
        "against the reference run of the same mesh (the time stepping's error alone).\n"
    )
    text += mesh_table(refs)
    for k in args.meshes:
        text += method_table(10 * 4**k + 2, sweeps[k])
    png = plot(sweeps)
    if png is not None:
        write_bytes(RESULTS / "shell_work_precision.png", png)
        text += "\n![first-apex error against wall time](shell_work_precision.png)\n"
    write_text(RESULTS / "shell_work_precision.md", text)
    print(text)


if __name__ == "__main__":
    main()
