"""What a tolerance achieves over nearby drops: the first-apex error of ``Scene.rtol`` on the six balls
of ``ball_family.py``, each dropped from five heights (0.94-1.06 times its own), the worst and the
RMS over the five.

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

import numpy as np  # noqa: E402
from accuracy import CONTROLS, NUMERICS, SWEEP_NODES, TOLERANCES  # noqa: E402
from ball_family import BALLS, ball_scene, first_apex, reference_scene  # noqa: E402

RESULTS = pathlib.Path(__file__).parent / "results"
HEIGHT_FACTORS = (0.94, 0.97, 1.0, 1.03, 1.06)  # the drops' start heights over the ball's own


def lifted(scene, factor):
    """``scene`` with its ring's start height (the centre's y, m) times ``factor``."""
    ring = scene.rings[0]
    position = (ring.position[0], ring.position[1] * factor)
    return dataclasses.replace(scene, rings=[dataclasses.replace(ring, position=position)])


def drop_errors(name, scene, references):
    """(H,) relative first-apex errors of ``scene`` dropped from each of :data:`HEIGHT_FACTORS`."""
    apexes = [first_apex(name, lifted(scene, f))[0] for f in HEIGHT_FACTORS]
    return np.abs(np.array(apexes) - references) / references


def spread(progress=print):
    """ball -> control -> [(rtol, worst error, RMS error) per tolerance]."""
    out = {}
    for name in BALLS:
        reference = reference_scene(name, n_nodes=SWEEP_NODES)
        references = np.array([first_apex(name, lifted(reference, f))[0] for f in HEIGHT_FACTORS])
        out[name] = {}
        for control in CONTROLS:
            rows = []
            for rtol in TOLERANCES:
                scene = ball_scene(name, SWEEP_NODES, rtol=rtol, contact_error=control, **NUMERICS)
                errors = drop_errors(name, scene, references)
                rows.append((rtol, float(errors.max()), float(np.sqrt(np.mean(errors**2)))))
            out[name][control] = rows
            progress(f"{name} {control}: " + ", ".join(f"{r:g} {w:.1e}" for r, w, _ in rows))
    return out


def report(results, seconds):
    """The markdown of results/accuracy_spread.md."""
    lines = [
        "# What a tolerance achieves over nearby drops",
        "",
        f"`python benchmarks/accuracy_spread.py` ({seconds / 60:.1f} min). Each ball of "
        f"`benchmarks/ball_family.py` dropped from {len(HEIGHT_FACTORS)} heights "
        f"({HEIGHT_FACTORS[0]:g}-{HEIGHT_FACTORS[-1]:g} times its own), each against its own reference; "
        "per tolerance the worst first-apex error over the drops (its ratio to rtol) and their RMS; "
        "monotone: the worst error fell at every tightening.",
        "",
        "| ball | control | "
        + " | ".join(f"rtol {t:g}: worst (worst/rtol), RMS" for t in TOLERANCES)
        + " | monotone |",
        "|---|---|" + "---:|" * len(TOLERANCES) + "---|",
    ]
    inside = {control: 0 for control in CONTROLS}
    falling = {control: 0 for control in CONTROLS}
    for name, by_control in results.items():
        for control, rows in by_control.items():
            cells = [f"{w:.1e} ({w / r:.2f}), {q:.1e}" for r, w, q in rows]
            falls = all(b[1] < a[1] for a, b in zip(rows, rows[1:], strict=False))
            inside[control] += sum(0.3 <= w / r <= 3.0 for r, w, _ in rows)
            falling[control] += falls
            lines.append(f"| {name} | {control} | " + " | ".join(cells) + f" | {'yes' if falls else 'no'} |")
    lines.append("")
    runs = len(results) * len(TOLERANCES)
    for control in CONTROLS:
        ratios = [w / r for by_control in results.values() for r, w, _ in by_control[control]]
        lines.append(
            f"- {control}: worst/rtol {min(ratios):.2f}-{max(ratios):.2f}, within 0.3-3 in {inside[control]} "
            f"of {runs}; the worst error falls at every tightening on {falling[control]} of {len(results)} "
            "balls."
        )
    return "\n".join(lines) + "\n"


def main():
    start = time.perf_counter()
    results = spread()
    text = report(results, time.perf_counter() - start)
    print(text)
    (RESULTS / "accuracy_spread.md").write_text(text)


if __name__ == "__main__":
    main()
