"""Cost of contact between rings: the barrier solved jointly against the explicit collision impulses.

    python benchmarks/ring_contact_cost.py     # writes benchmarks/results/ring_contact_cost.md

Scenes (each run with ``Scene.self_intersection = "barrier"``, the joint implicit step of rings in
contact, and ``"reject"``, the explicit impulses with their push-out): a head-on collision of two
N = 32 balls at 3 m/s each (0.03 s), five balls stacked in a box 6 mm wider than a ball (3 s) and
eight balls thrown into a box (3 s, ``impulse_tol`` = 5e-4 N s; ``tests/physics/walls/test_impulses.py``).
Reported: wall time (numba warm, best of two), accepted and rejected steps, Newton corrections,
the largest kinetic energy over the last 0.5 s (jiggle), the largest rise of the total energy (with
the contact energy between rings) above its start, and the energy the impulses' push-out created.

Detection: one call of the pair search of the barrier (:func:`ring_contact.find_ring_pairs`, broad
phase on the rings' boxes, then the nodes and edges near the other ring) and of the impulses'
contacts (:func:`collision.find_contacts`), on the touching lattice of ``collision_cost.py``, for
2-64 rings of 32 and 128 nodes (median of repeats).
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import pathlib  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from dataclasses import replace  # noqa: E402

import numpy as np  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from collision_cost import NODES, RINGS, lattice  # noqa: E402

from ballenv.files import write_text  # noqa: E402
from ballenv.physics import Ring, Scene, simulate  # noqa: E402
from ballenv.physics.build import build_collision_workspace, build_model, build_ring_contact_workspace  # noqa: E402
from ballenv.physics.walls.impulses import find_contacts  # noqa: E402
from ballenv.physics.walls.ring_barrier import find_ring_pairs  # noqa: E402
from tests.physics.walls import test_impulses as collision_tests  # noqa: E402
from tests.physics.walls.test_impulses import mirrored_pair  # noqa: E402
from tests.physics.walls.test_ring_barrier import five_balls  # noqa: E402

RESULTS = ROOT / "benchmarks" / "results"
MODES = ("barrier", "reject")


def head_on(mode):
    rings, x0, v0, _ = mirrored_pair(32, 3.0)
    scene = Scene(rings=rings, gravity=0.0, dt=1e-3, adaptive=True, self_intersection=mode)
    return scene, 0.03, {"x0": x0, "v0": v0}


def stacked(mode):
    return five_balls(mode), 3.0, {"output_dt": 0.01}


def eight_balls(mode):
    return replace(collision_tests.eight_balls(), self_intersection=mode), 3.0, {"output_dt": 0.01}


SCENES = {"head-on, 2 balls": head_on, "5 balls stacked": stacked, "8 balls in a box": eight_balls}


def run(make, mode):
    """One scene's row: the best wall time of two runs and the run's figures."""
    scene, t_end, kw = make(mode)
    best = np.inf
    for _ in range(2):
        start = time.perf_counter()
        traj = simulate(scene, t_end, **kw)
        best = min(best, time.perf_counter() - start)
    parts = traj.energy()
    total = parts["total"].sum(axis=1)
    late = traj.t >= traj.t[-1] - 0.5
    s = traj.stats
    return {
        "wall": best,
        "steps": s.steps,
        "rejected": s.rejected_steps,
        "newton": s.newton_iterations,
        "jiggle": parts["kinetic"].sum(axis=1)[late].max(),
        "rise": max(0.0, total.max() - total[0]),
        "gain": s.collision_gain,
    }


def detection_cost(repeats=200):
    """{(R, N): (barrier pair search s, impulse contacts s)} per call."""
    out = {}
    for n_nodes in NODES:
        for n_rings in RINGS:
            x = np.ascontiguousarray(lattice(n_rings, n_nodes))
            rings = [Ring(radius=0.1, n_nodes=n_nodes, position=(3.0 * k, 0.0)) for k in range(n_rings)]
            model = build_model(Scene(rings=rings, gravity=0.0))
            rw = build_ring_contact_workspace(n_rings, n_nodes)
            cw = build_collision_workspace(n_rings, n_nodes)
            times = []
            for fn, args in ((find_ring_pairs, (model, x, x, rw)), (find_contacts, (x, model.thickness, cw))):
                fn(*args)
                samples = []
                for _ in range(repeats):
                    start = time.perf_counter()
                    fn(*args)
                    samples.append(time.perf_counter() - start)
                times.append(float(np.median(samples)))
            out[(n_rings, n_nodes)] = tuple(times)
    return out


def main():
    rows = {(name, mode): run(make, mode) for name, make in SCENES.items() for mode in MODES}
    lines = [
        "# Contact between rings: the barrier's joint step against the explicit impulses",
        "",
        "`python benchmarks/ring_contact_cost.py`; numba warm, wall time the best of two runs.",
        "",
        "| scene | contact | wall (s) | steps | rejected | Newton | KE last 0.5 s (J) | energy rise (J) "
        "| push-out gain (J) |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for (name, mode), r in rows.items():
        label = "barrier, joint" if mode == "barrier" else "impulses"
        lines.append(
            f"| {name} | {label} | {r['wall']:.2f} | {r['steps']:,} | {r['rejected']:,} | {r['newton']:,} | "
            f"{r['jiggle']:.2g} | {r['rise']:.2g} | {r['gain']:.2g} |"
        )
    lines += [
        "",
        "## Detection, one call (us)",
        "",
        "Touching rings on a square lattice (`collision_cost.py`): the barrier's candidate pairs",
        "(`find_ring_pairs`) and the impulses' contacts (`find_contacts`).",
        "",
        "| rings | nodes | barrier pairs | impulse contacts |",
        "|---:|---:|---:|---:|",
    ]
    for (n_rings, n_nodes), (pairs, contacts) in detection_cost().items():
        lines.append(f"| {n_rings} | {n_nodes} | {pairs * 1e6:.1f} | {contacts * 1e6:.1f} |")
    RESULTS.mkdir(exist_ok=True)
    write_text(RESULTS / "ring_contact_cost.md", "\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
