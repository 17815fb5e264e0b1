"""Accuracy you ask for: the first-apex error that a requested tolerance ``Scene.rtol`` achieves on six
balls that differ in what dominates them (``ball_family.py``), its cost, and the fidelity presets on
the same balls.

    python benchmarks/accuracy.py          # writes benchmarks/results/accuracy.md and .png
    python benchmarks/accuracy.py --quick  # two tolerances, the references from the cache

Error: the first-apex height of the centre of mass, relative to the ball's converged reference
(``ball_family.reference_apex``: the contact impulse per step at most 5e-5 ``M sqrt(g R)``, its own
error estimated against twice that). The references are cached in
``benchmarks/results/accuracy_references.json`` (``--references`` recomputes them: about 6
minutes). Cost: wall time (median of three runs, numba warm), accepted and rejected steps. All
runs: generalized-alpha, ``rho_infinity`` = 0.9, adaptive, largest step 10 ms, N = 64. Under
``rtol`` the step in contact follows the contact errors of ``ballenv/physics/contact_error.py``
(step doubling, the arriving nodes' distance still to go, the contact impulse at most
``2 sqrt(rtol) M sqrt(g R)``); the table says per ball whether the error fell at every tightening
of ``rtol``, and the range of achieved over requested.
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import pathlib  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402

from ball_family import BALLS, ball_scene, first_apex, gas_to_bending, reference_apex  # noqa: E402

from ballenv.physics import SimulationError  # noqa: E402
from ballenv.physics.presets import FIDELITY_PRESETS, with_fidelity  # noqa: E402

RESULTS = pathlib.Path(__file__).parent / "results"
REFERENCES = RESULTS / "accuracy_references.json"
TOLERANCES = (3e-2, 1e-2, 3e-3, 1e-3)
NUMERICS = dict(adaptive=True, dt=1e-2, rho_infinity=0.9)


def references(recompute=False):
    """ball -> {"apex": reference first apex (m), "uncertainty": relative change at twice its tolerance}."""
    if REFERENCES.exists() and not recompute:
        return json.loads(REFERENCES.read_text())
    refs = {}
    for name in BALLS:
        fine, uncertainty = reference_apex(name)
        refs[name] = {"apex": fine, "uncertainty": uncertainty}
        print(f"reference {name}: {fine:.6f} m (+- {refs[name]['uncertainty']:.1e})", flush=True)
    REFERENCES.write_text(json.dumps(refs, indent=1) + "\n")
    return refs


def measure(name, scene, reference, repeats=3):
    """One run of ball ``name``: error, wall (s), steps, rejected steps; error NaN if it failed."""
    walls = []
    for _ in range(repeats + 1):  # the first run warms numba's cache
        t0 = time.perf_counter()
        try:
            apex, traj = first_apex(name, scene)
        except SimulationError as failure:
            return {"error": math.nan, "wall": math.nan, "steps": 0, "rejected": 0, "failure": str(failure)}
        walls.append(time.perf_counter() - t0)
    return {
        "error": abs(apex - reference) / reference,
        "wall": statistics.median(walls[1:]),
        "steps": traj.stats.steps,
        "rejected": traj.stats.rejected_steps,
    }


def sweep(refs, tolerances, progress=print):
    """ball -> {"rtol=x": run, preset name: run}."""
    runs = {}
    for name in BALLS:
        ref = refs[name]["apex"]
        runs[name] = {}
        for rtol in tolerances:
            runs[name][f"rtol={rtol:g}"] = measure(name, ball_scene(name, rtol=rtol, **NUMERICS), ref)
        for preset in FIDELITY_PRESETS:  # node count as the preset says; reference at N = 64
            runs[name][preset] = measure(name, with_fidelity(ball_scene(name), preset), ref)
        progress(f"{name}: " + ", ".join(f"{k} {v['error']:.1e}" for k, v in runs[name].items()))
    return runs


def report(refs, runs, tolerances):
    """The markdown of results/accuracy.md."""
    lines = [
        "# Accuracy you ask for: achieved first-apex error per requested `rtol`",
        "",
        "`python benchmarks/accuracy.py` (balls: `benchmarks/ball_family.py`; generalized-alpha, "
        "rho_inf 0.9, adaptive, largest step 10 ms, N = 64). Error: first-apex height relative to the "
        "ball's converged reference; `err/rtol`: achieved over requested; monotone: the error fell at "
        "every tightening of rtol. Under rtol the contact errors of `ballenv/physics/contact_error.py` "
        "control the step in contact.",
        "",
        "| ball | p R^3/EI | reference apex (m) | ref. uncertainty | "
        + " | ".join(f"rtol {t:g}: err (err/rtol), wall ms, steps" for t in tolerances)
        + " | monotone |",
        "|---|---:|---:|---:|" + "---:|" * len(tolerances) + "---|",
    ]
    ratios = []
    for name in BALLS:
        cells = []
        errors = [runs[name][f"rtol={t:g}"]["error"] for t in tolerances]
        for t in tolerances:
            r = runs[name][f"rtol={t:g}"]
            ratios.append(r["error"] / t)
            cells.append(f"{r['error']:.1e} ({r['error'] / t:.2f}), {r['wall'] * 1e3:.0f}, {r['steps']}")
        monotone = "yes" if all(b < a for a, b in zip(errors, errors[1:], strict=False)) else "no"
        lines.append(
            f"| {name} | {gas_to_bending(name):,.1f} | {refs[name]['apex']:.5f} | "
            f"{refs[name]['uncertainty']:.0e} | " + " | ".join(cells) + f" | {monotone} |"
        )
    inside = sum(0.3 <= q <= 3.0 for q in ratios)
    lines += [
        "",
        f"err/rtol: {min(ratios):.2f}-{max(ratios):.2f}; within 0.3-3: {inside} of {len(ratios)} runs.",
    ]
    lines += ["", "The fidelity presets (their own node counts; error against the N = 64 reference):", ""]
    lines += ["| ball | " + " | ".join(f"{p}: err, wall ms" for p in FIDELITY_PRESETS) + " |"]
    lines += ["|---|" + "---:|" * len(FIDELITY_PRESETS)]
    for name in BALLS:
        cells = [f"{runs[name][p]['error']:.1e}, {runs[name][p]['wall'] * 1e3:.0f}" for p in FIDELITY_PRESETS]
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def plot(runs, tolerances, path):
    """Work-precision per ball (left) and achieved error over rtol (right)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax_wp, ax_ratio) = plt.subplots(1, 2, figsize=(11, 4.2))
    for name in BALLS:
        rs = [runs[name][f"rtol={t:g}"] for t in tolerances]
        ax_wp.loglog([r["wall"] * 1e3 for r in rs], [r["error"] for r in rs], "o-", label=name)
        ratios = [r["error"] / t for r, t in zip(rs, tolerances, strict=True)]
        ax_ratio.loglog(tolerances, ratios, "o-", label=name)
    ax_wp.set(xlabel="wall time (ms)", ylabel="first-apex error (relative)", title="work-precision")
    ax_ratio.axhspan(0.3, 3.0, color="0.9", label="0.3-3x")
    ax_ratio.set(xlabel="requested rtol", ylabel="achieved error / rtol", title="tolerance proportionality")
    ax_ratio.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="two tolerances; no files written")
    parser.add_argument("--references", action="store_true", help="recompute the cached references")
    args = parser.parse_args(argv)
    refs = references(args.references)
    tolerances = TOLERANCES[1::2] if args.quick else TOLERANCES
    runs = sweep(refs, tolerances)
    text = report(refs, runs, tolerances)
    print(text)
    if not args.quick:
        (RESULTS / "accuracy.md").write_text(text)
        plot(runs, tolerances, RESULTS / "accuracy.png")


if __name__ == "__main__":
    main()
