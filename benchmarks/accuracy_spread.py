"""What a tolerance achieves over nearby drops: the first-apex and trajectory errors of ``Scene.rtol``
on the six balls of ``ball_family.py``, each dropped from five heights (0.94-1.06 times its own):
the worst first-apex error and the RMS over the five, and the worst trajectory error (the largest
distance between the run's centre of mass and the reference's until the reference's first apex,
over its height; the run's centre between its steps is the cubic Hermite spline through its
recorded positions and velocities, exact in flight).

    python benchmarks/accuracy_spread.py   # writes benchmarks/results/accuracy_spread.md (about 5 min)

One drop's error rises and falls with where the steps happen to fall in its contact (the same run
with a 1 ms output grid gave errors up to 11x apart), so ``accuracy.py``'s single drop per ball
says little about monotonicity or proportionality. Each height has its own reference (the
reference control of ``ball_family.reference_scene``), computed here and not cached. Numerics as in
``accuracy.py``: generalized-alpha, ``rho_infinity`` 0.9, adaptive, largest step 10 ms, N = 64, both
controls of the step in contact (``Scene.contact_error``).
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import dataclasses  # noqa: E402
import pathlib  # noqa: E402
import time  # noqa: E402

import numpy as np
from accuracy import CONTROLS, NUMERICS, SWEEP_NODES, TOLERANCES, falls_at_every_tightening  # noqa: E402
from ball_family import BALLS, ball_scene, first_apex, reference_scene  # noqa: E402
from scipy.interpolate import CubicHermiteSpline  # noqa: E402

from ballenv.files import write_text  # noqa: E402

RESULTS = pathlib.Path(__file__).parent / "results"
HEIGHT_FACTORS = (0.94, 0.97, 1.0, 1.03, 1.06)  # the drops' start heights over the ball's own


def lifted(scene, factor):
    """``scene`` with its ring's start height (the centre's y, m) times ``factor``."""
    ring = scene.rings[0]
    position = (ring.position[0], ring.position[1] * factor)
    return dataclasses.replace(scene, rings=[dataclasses.replace(ring, position=position)])


def centre_path(traj):
    """Ring 0's centre of mass as a cubic Hermite spline of time (m), through its recorded positions
    and velocities: exact on a flight's parabola whatever the steps."""
    t, keep = np.unique(traj.t, return_index=True)
    centre = traj.centre_of_mass()[keep, 0]
    return CubicHermiteSpline(t, centre, traj.v[keep, 0].mean(axis=1), axis=0)  # equal node masses


def reference_drops(name):
    """Ball ``name``'s reference run dropped from each of :data:`HEIGHT_FACTORS`: (H,) first apexes
    (m) and H (times (s), centre-of-mass positions (m)) of its records up to its first apex."""
    reference = reference_scene(name, n_nodes=SWEEP_NODES)
    apexes, paths = [], []
    for f in HEIGHT_FACTORS:
        apex, traj = first_apex(name, lifted(reference, f))
        apexes.append(apex)
        until = traj.t <= traj.apexes()[0, 0]
        paths.append((traj.t[until], traj.centre_of_mass()[until, 0]))
    return np.array(apexes), paths


def drop_errors(name, scene, references, paths):
    """(H,) relative first-apex errors and (H,) trajectory errors of ``scene`` dropped from each of
    :data:`HEIGHT_FACTORS` against the reference drops (:func:`reference_drops`). Trajectory error:
    the largest distance (m) between the run's centre of mass and the reference's until the
    reference's first apex, at the reference's records, over that apex's height (m)."""
    apex_errors, path_errors = [], []
    for f, reference, (t, centre) in zip(HEIGHT_FACTORS, references, paths, strict=True):
        apex, traj = first_apex(name, lifted(scene, f))
        apex_errors.append(abs(apex - reference) / reference)
        distance = np.hypot(*(centre_path(traj)(t) - centre).T)
        path_errors.append(distance.max() / reference)
    return np.array(apex_errors), np.array(path_errors)


def spread(progress=print):
    """ball -> control -> [(rtol, worst apex error, RMS apex error, worst trajectory error) per
    tolerance]."""
    out = {}
    for name in BALLS:
        references, paths = reference_drops(name)
        out[name] = {}
        for control in CONTROLS:
            rows = []
            for rtol in TOLERANCES:
                scene = ball_scene(name, SWEEP_NODES, rtol=rtol, contact_error=control, **NUMERICS)
                apex, path = drop_errors(name, scene, references, paths)
                rows.append((rtol, float(apex.max()), float(np.sqrt(np.mean(apex**2))), float(path.max())))
            out[name][control] = rows
            progress(f"{name} {control}: " + ", ".join(f"{r:g} {w:.1e} {p:.1e}" for r, w, _, p in rows))
    return out


MEASURES = {"worst": 1, "RMS": 2, "trajectory": 3}  # a row's columns: (rtol, worst, RMS, trajectory)


def falls(rows, column):
    """Whether column ``column`` of ``rows`` (one per tolerance, loosest first) falls at every
    tightening."""
    return falls_at_every_tightening([row[column] for row in rows])


def summary(results, control):
    """The summary line of ``control``: per measure, its range over rtol and how often it lies within
    0.3-3 rtol, and on how many balls it falls at every tightening."""
    parts = []
    for measure, column in MEASURES.items():
        rows = [row for by_control in results.values() for row in by_control[control]]
        ratios = [row[column] / row[0] for row in rows]
        inside = sum(0.3 <= r <= 3.0 for r in ratios)
        falling = sum(falls(by_control[control], column) for by_control in results.values())
        parts.append(
            f"{measure} {min(ratios):.2f}-{max(ratios):.2f} rtol ({inside} of {len(ratios)} within "
            f"0.3-3), falling on {falling} of {len(results)} balls"
        )
    return f"- {control}: " + "; ".join(parts) + "."


def report(results, seconds):
    """The markdown of results/accuracy_spread.md."""
    lines = [
        "# What a tolerance achieves over nearby drops",
        "",
        f"`python benchmarks/accuracy_spread.py` ({seconds / 60:.1f} min). Each ball of "
        f"`benchmarks/ball_family.py` dropped from {len(HEIGHT_FACTORS)} heights "
        f"({HEIGHT_FACTORS[0]:g}-{HEIGHT_FACTORS[-1]:g} times its own), each against its own reference. "
        "Per tolerance: the worst first-apex error over the drops (its ratio to rtol), their RMS, and the "
        "worst trajectory error (the largest distance between the run's centre of mass and the "
        "reference's until the reference's first apex, over its height; its ratio to rtol). "
        "Falls: whether worst / RMS / trajectory fell at every tightening.",
        "",
        "| ball | control | "
        + " | ".join(f"rtol {t:g}: worst (/rtol), RMS, trajectory (/rtol)" for t in TOLERANCES)
        + " | falls: worst / RMS / trajectory |",
        "|---|---|" + "---:|" * len(TOLERANCES) + "---|",
    ]
    for name, by_control in results.items():
        for control, rows in by_control.items():
            cells = [f"{w:.1e} ({w / r:.2f}), {q:.1e}, {p:.1e} ({p / r:.2f})" for r, w, q, p in rows]
            fell = " / ".join("yes" if falls(rows, c) else "no" for c in MEASURES.values())
            lines.append(f"| {name} | {control} | " + " | ".join(cells) + f" | {fell} |")
    lines.append("")
    lines += [summary(results, control) for control in CONTROLS]
    return "\n".join(lines) + "\n"


def main():
    start = time.perf_counter()
    results = spread()
    text = report(results, time.perf_counter() - start)
    print(text)
    write_text(RESULTS / "accuracy_spread.md", text)


if __name__ == "__main__":
    main()
