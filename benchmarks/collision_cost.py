"""Cost of ring-ring collision detection: broad phase (sort-and-sweep of bounding boxes) + narrow
phase, against the paper's all-pairs node test, for 2-64 rings of 32 and 128 nodes.

    python benchmarks/collision_cost.py     # writes benchmarks/results/collision_cost.md and .png

Scene: rings of radius 0.1 m (wall 2 mm) on a square lattice, each touching its neighbours (centres
2 r + 3 mm apart: every neighbour pair has nodes within the 4 mm contact distance), as balls
settled in a box. Both methods return the same contacts (checked here, and in
tests/physics/walls/test_impulses.py). Time: median of repeats of one detection call, numba warm.
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import math  # noqa: E402
import pathlib  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402
from tqdm.auto import tqdm  # noqa: E402

from ballenv.files import write_text  # noqa: E402
from ballenv.physics.build import build_collision_workspace  # noqa: E402
from ballenv.physics.walls.impulses import CONTACT_COLUMNS, find_contacts, find_contacts_all_pairs  # noqa: E402

RESULTS = pathlib.Path(__file__).parent / "results"
RINGS = (2, 8, 32, 64)
NODES = (32, 128)
RADIUS = 0.1
THICKNESS = 2e-3


def lattice(n_rings, n_nodes):
    """(R, N, 2) node positions of ``n_rings`` touching rings on a square lattice."""
    side = math.ceil(math.sqrt(n_rings))
    pitch = 2.0 * RADIUS + 3e-3
    theta = 2.0 * np.pi * np.arange(n_nodes) / n_nodes
    circle = RADIUS * np.stack([np.cos(theta), np.sin(theta)], axis=1)
    return np.stack([circle + (pitch * (k % side), pitch * (k // side)) for k in range(n_rings)])


def timed(fn, repeats):
    fn()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        count = fn()
        times.append(time.perf_counter() - start)
    return float(np.median(times)), count


def main():
    start = time.perf_counter()
    x = lattice(2, 8)
    thick = np.full(2, THICKNESS)
    find_contacts(x, thick, build_collision_workspace(2, 8))
    find_contacts_all_pairs(x, thick, np.zeros((64, CONTACT_COLUMNS)))
    compile_s = time.perf_counter() - start
    rows = []
    for n_nodes in NODES:
        for n_rings in tqdm(RINGS, desc=f"N = {n_nodes}"):
            x = lattice(n_rings, n_nodes)
            thick = np.full(n_rings, THICKNESS)
            cw = build_collision_workspace(n_rings, n_nodes)
            ref = np.zeros((n_rings * n_rings * n_nodes, CONTACT_COLUMNS))
            repeats = 21 if n_rings * n_nodes <= 2048 else 5
            t_fast, count = timed(lambda x=x, t=thick, cw=cw: find_contacts(x, t, cw), repeats)
            t_ref, ref_count = timed(
                lambda x=x, t=thick, ref=ref: find_contacts_all_pairs(x, t, ref), repeats
            )
            assert count == ref_count, (count, ref_count)
            rows.append((n_nodes, n_rings, count, t_fast, t_ref))
    lines = [
        "# Ring-ring collision detection cost",
        "",
        "Touching rings on a square lattice (R = 0.1 m, h = 2 mm); median wall time of one detection",
        f"call, numba warm. First-call compile of both kernels: {compile_s:.1f} s.",
        "",
        "| nodes per ring | rings | contacts | broad + narrow (us) | all pairs (us) | speed-up |",
        "|---:|---:|---:|---:|---:|---:|",
    ]
    for n_nodes, n_rings, count, t_fast, t_ref in rows:
        times = f"{t_fast * 1e6:,.1f} | {t_ref * 1e6:,.1f} | {t_ref / t_fast:,.1f}"
        lines.append(f"| {n_nodes} | {n_rings} | {count} | {times} |")
    lines.append("")
    for n_nodes in NODES:
        sel = [r for r in rows if r[0] == n_nodes]
        growth = sel[-1][3] / sel[1][3]
        ref_growth = sel[-1][4] / sel[1][4]
        lines.append(
            f"* N = {n_nodes}, 8 -> 64 rings (x8): broad + narrow x{growth:.1f}, all pairs x{ref_growth:.1f}."
        )
    text = "\n".join(lines) + "\n"
    RESULTS.mkdir(exist_ok=True)
    write_text(RESULTS / "collision_cost.md", text)
    print(text)
    _plot(rows)


def _plot(rows):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    for n_nodes, style in zip(NODES, ("o", "s"), strict=True):
        sel = [r for r in rows if r[0] == n_nodes]
        rings = [r[1] for r in sel]
        ax.loglog(rings, [r[3] * 1e6 for r in sel], style + "-", label=f"broad + narrow, N = {n_nodes}")
        ax.loglog(rings, [r[4] * 1e6 for r in sel], style + "--", label=f"all pairs (paper), N = {n_nodes}")
    ref = np.array(RINGS, dtype=float)
    ax.loglog(ref, ref * rows[0][3] * 1e6 / 2, ":", color="grey", label="linear in rings")
    ax.set_xlabel("rings")
    ax.set_ylabel("detection time per call (us)")
    ax.set_title("Ring-ring collision detection")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(RESULTS / "collision_cost.png", dpi=120)


if __name__ == "__main__":
    main()
