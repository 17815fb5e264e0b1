"""The 3-D ball's fidelity presets measured: each preset's first-apex error and wall time on three
balls, against converged runs of the same ball on the preset's mesh, and each mesh's own error
against the finest.

    taskset -c 0 python benchmarks/shell_presets.py    # writes results/shell_presets.md and
                                                       # results/shell_references.json
    taskset -c 0 python benchmarks/shell_presets.py --keep-references   # the presets' runs only

The balls (``BALLS``): the default ball (``Shell()``: R = 0.12 m, E = 5 MPa, h = 3 mm, 55 kPa), a
soft one (E = 2 MPa, 15 kPa) and a small stiff one (R = 33 mm, E = 10 MPa, h = 3 mm, 80 kPa),
each dropped from a centre height of 0.5 m onto a flat ground with friction 0.5 and simulated to
its first apex. Each preset also runs with its ``rtol`` scaled by ``RTOL_SCALES``: the first
apex of a run whose Newton or step error is near a decision (a step accepted or rejected, one
Newton iteration more or less) moves with such a change as it does with the rounding of another
CPU, and the worst of these errors is the one the preset's bound must cover. References:
generalized-alpha (rho_inf = 0.9) at ``REFERENCE_RTOL`` on 162 and 642 vertices,
``REFERENCE_RTOL_FINEST`` on 2562 (its cost); ``tests/shell/test_presets.py`` reads them from the
JSON file. Wall time: ``Trajectory.stats.wall_time``, numba warm, one core.
"""

import argparse
import dataclasses
import json
import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import pathlib  # noqa: E402
import time  # noqa: E402

from ballenv.files import write_text  # noqa: E402
from ballenv.shell import Ground, Scene, Shell, simulate  # noqa: E402
from ballenv.shell.presets import FIDELITY_PRESETS, with_fidelity  # noqa: E402

RESULTS = pathlib.Path(__file__).parent / "results"
REFERENCES = RESULTS / "shell_references.json"
DROP = 0.5  # m
T_END = 0.9  # s: after every ball's first apex
REFERENCE_RTOL = 1e-6
REFERENCE_RTOL_FINEST = 1e-5
MESHES = (2, 3, 4)
RTOL_SCALES = (0.97, 0.99, 1.01, 1.03)
BALLS = {
    "default": {},
    "soft": {"youngs_modulus": 2e6, "pressure": 15e3},
    "small_stiff": {"radius": 0.033, "youngs_modulus": 10e6, "pressure": 80e3},
}


def ball_scene(ball: str, subdivisions: int = 2) -> Scene:
    """The drop of ``ball`` (module doc) on the ``subdivisions`` icosphere, ``Scene`` defaults."""
    shell = Shell(subdivisions=subdivisions, position=(0.0, 0.0, DROP), **BALLS[ball])
    return Scene(shells=[shell], grounds=[Ground(friction=0.5)])


def first_apex(scene: Scene) -> tuple[float, float]:
    """The first apex's height (m) and the stepping's wall time (s)."""
    traj = simulate(scene, t_end=T_END, output_dt=0.01)  # the apex is located in its step
    apexes = traj.apexes()
    return (float(apexes[0, 1]) if len(apexes) else float("nan")), traj.stats.wall_time


def reference(ball: str, subdivisions: int) -> float:
    """The converged first apex (m) of ``ball`` on the ``subdivisions`` mesh."""
    rtol = REFERENCE_RTOL_FINEST if subdivisions == MESHES[-1] else REFERENCE_RTOL
    scene = ball_scene(ball, subdivisions)
    return first_apex(Scene(shells=scene.shells, grounds=scene.grounds, rtol=rtol))[0]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--keep-references", action="store_true", help="read the references from the JSON file"
    )
    args = parser.parse_args()
    clock = time.perf_counter()
    if args.keep_references:
        refs = json.loads(REFERENCES.read_text())
    else:
        refs = {str(k): {ball: reference(ball, k) for ball in BALLS} for k in MESHES}
        write_text(REFERENCES, json.dumps(refs, indent=1) + "\n")
    first_apex(with_fidelity(ball_scene("default"), "fast"))  # compiles: every wall below is warm
    rows = []
    for preset, numerics in FIDELITY_PRESETS.items():
        for ball in BALLS:
            scene = with_fidelity(ball_scene(ball), preset)
            apex, wall = first_apex(scene)
            ref = refs[str(numerics["subdivisions"])][ball]
            scaled = [first_apex(dataclasses.replace(scene, rtol=c * scene.rtol))[0] for c in RTOL_SCALES]
            worst = max(abs(a - ref) / ref for a in (apex, *scaled))
            rows.append((preset, ball, apex, (apex - ref) / ref, worst, wall, numerics["apex_error_bound"]))
    finest = refs[str(MESHES[-1])]
    text = (
        "# The 3-D ball's fidelity presets\n\n"
        f"`python benchmarks/shell_presets.py` (see its docstring), "
        f"{(time.perf_counter() - clock) / 60:.0f} min on the shared 2-core machine"
        f"{' (the references read from the JSON file)' if args.keep_references else ''}.\n\n"
        "## Each preset against a converged run on its mesh\n\n"
        "The worst error is the largest of the run's and those of its step control's `rtol` scaled by "
        + ", ".join(f"{c:g}" for c in RTOL_SCALES)
        + " (the module doc).\n\n"
        "| preset | ball | first apex (m) | error | worst error | bound | wall to the apex (s) |\n"
        "|---|---|---:|---:|---:|---:|---:|\n"
    )
    text += "".join(
        f"| {p} | {b} | {a:.5f} | {100 * e:+.2f} % | {100 * worst:.2f} % | {100 * bound:g} % | {w:.2f} |\n"
        for p, b, a, e, worst, w, bound in rows
    )
    text += (
        "\n## Each mesh against the finest (converged runs)\n\n| ball | "
        + " | ".join(f"{10 * 4**k + 2} vertices" for k in MESHES)
        + " |\n|---|"
        + "---:|" * len(MESHES)
        + "\n"
    )
    text += "".join(
        f"| {ball} | "
        + " | ".join(
            f"{refs[str(k)][ball]:.5f} ({100 * (refs[str(k)][ball] / finest[ball] - 1):+.2f} %)"
            for k in MESHES
        )
        + " |\n"
        for ball in BALLS
    )
    write_text(RESULTS / "shell_presets.md", text)
    print(text)


if __name__ == "__main__":
    main()
