"""Accuracy you ask for: the first-apex error that a requested tolerance ``Scene.rtol`` achieves on six
balls that differ in what dominates them (``ball_family.py``), its cost, the fidelity presets on
the same balls against their stated bounds, the node count's own error, and ``Scene``'s default step
against the former fixed 0.1 ms steps.

    python benchmarks/accuracy.py          # writes benchmarks/results/accuracy.md and .png
    python benchmarks/accuracy.py --quick  # two tolerances, the references from the cache

Error: the first-apex height of the centre of mass, relative to the ball's converged reference
(``ball_family.reference_apex``: the contact impulse per step at most 5e-5 ``M sqrt(g R)``, its own
error estimated against twice that), at N = 64 and at the presets' node counts. The references are
cached in ``benchmarks/results/accuracy_references.json`` (``--references`` recomputes them: about
10 minutes). Cost: wall time (median of three runs, numba warm), accepted and rejected steps. The
sweep: generalized-alpha, ``rho_infinity`` = 0.9, adaptive, largest step 10 ms, N = 64. Each
tolerance with both controls of the step in contact (``Scene.contact_error``): "impulse" (the
contact impulse at most ``rtol M sqrt(g R)``) and "doubling" (the contact errors of
``ballenv/physics/step/contact_error.py``); the table says per ball and control whether the error fell at
every tightening of ``rtol``, and the range of achieved over requested.
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import dataclasses  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import pathlib  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402

from ball_family import BALLS, ball_scene, first_apex, gas_to_bending, reference_apex  # noqa: E402

from ballenv.files import write_text  # noqa: E402
from ballenv.physics import Ground, SimulationError, simulate  # noqa: E402
from ballenv.physics.build import initial_state  # noqa: E402
from ballenv.physics.presets import FIDELITY_PRESETS, with_fidelity  # noqa: E402
from ballenv.physics.scene import DEFAULT_RTOL  # noqa: E402

RESULTS = pathlib.Path(__file__).parent / "results"
REFERENCES = RESULTS / "accuracy_references.json"
TOLERANCES = (3e-2, 1e-2, 3e-3, 1e-3)
CONTROLS = ("impulse", "doubling")  # Scene.contact_error
NUMERICS = dict(adaptive=True, dt=1e-2, rho_infinity=0.9)
SWEEP_NODES = 64  # node count of the rtol sweep
FORMER_DEFAULT = dict(adaptive=False, dt=1e-4)  # Scene's step before it was error-controlled
REST_SECONDS = 30.0  # s: the ball at rest of the default's table
# Scene's default step is the sweep's NUMERICS with rtol DEFAULT_RTOL and the "impulse" control
# (tests/physics/test_scene.py checks the defaults): its runs are that row of the sweep
DEFAULT_RUN = f"impulse rtol={DEFAULT_RTOL:g}"
REFERENCE_NODES = sorted({SWEEP_NODES} | {p["n_nodes"] for p in FIDELITY_PRESETS.values()})


def references(recompute=False):
    """node count (str) -> ball -> {"apex": reference first apex (m), "uncertainty": relative change at
    twice its tolerance}, for the node counts of the sweep and of the presets."""
    if REFERENCES.exists() and not recompute:
        return json.loads(REFERENCES.read_text())
    refs = {}
    for n_nodes in REFERENCE_NODES:
        refs[str(n_nodes)] = by_ball = {}
        for name in BALLS:
            fine, uncertainty = reference_apex(name, n_nodes=n_nodes)
            by_ball[name] = {"apex": fine, "uncertainty": uncertainty}
            print(f"reference {name}, N = {n_nodes}: {fine:.6f} m (+- {uncertainty:.1e})", flush=True)
    write_text(REFERENCES, json.dumps(refs, indent=1) + "\n")
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
    """ball -> {"<control> rtol=x": run, preset name: run}."""
    runs = {}
    for name in BALLS:
        ref = refs[str(SWEEP_NODES)][name]["apex"]
        runs[name] = {}
        for control in CONTROLS:
            for rtol in tolerances:
                scene = ball_scene(name, SWEEP_NODES, rtol=rtol, contact_error=control, **NUMERICS)
                runs[name][f"{control} rtol={rtol:g}"] = measure(name, scene, ref)
        for preset, numerics in FIDELITY_PRESETS.items():  # against the reference at its node count
            preset_ref = refs[str(numerics["n_nodes"])][name]["apex"]
            runs[name][preset] = measure(name, with_fidelity(ball_scene(name), preset), preset_ref)
        runs[name]["former default"] = measure(name, ball_scene(name, SWEEP_NODES, **FORMER_DEFAULT), ref, 1)
        progress(f"{name}: " + ", ".join(f"{k} {v['error']:.1e}" for k, v in runs[name].items()))
    return runs


def report(refs, runs, tolerances):
    """The markdown of results/accuracy.md."""
    lines = ["# Accuracy you ask for: achieved first-apex error per requested `rtol`", ""]
    tables = sweep_table(refs, runs, tolerances) + preset_table(runs) + node_table(refs) + default_table(runs)
    return "\n".join(lines + tables) + "\n"


def falls_at_every_tightening(errors):
    """Whether ``errors`` (one per tolerance, loosest first) fall at every tightening."""
    return all(b < a for a, b in zip(errors, errors[1:], strict=False))


def sweep_table(refs, runs, tolerances):
    """Per ball and contact control: error, err/rtol, wall and steps per tolerance."""
    sweep_refs = refs[str(SWEEP_NODES)]
    lines = [
        "`python benchmarks/accuracy.py` (balls: `benchmarks/ball_family.py`; generalized-alpha, "
        f"rho_inf 0.9, adaptive, largest step 10 ms, N = {SWEEP_NODES}). Error: first-apex height relative "
        "to the ball's converged reference; `err/rtol`: achieved over requested; monotone: the error fell "
        "at every tightening of rtol. Control: `Scene.contact_error`, impulse (the contact impulse at most "
        "rtol M sqrt(g R), the default) or doubling (the contact errors of "
        "`ballenv/physics/step/contact_error.py`).",
        "",
        "| ball | control | p R^3/EI | reference apex (m) | ref. uncertainty | "
        + " | ".join(f"rtol {t:g}: err (err/rtol), wall ms, steps" for t in tolerances)
        + " | monotone |",
        "|---|---|---:|---:|---:|" + "---:|" * len(tolerances) + "---|",
    ]
    ratios = {control: [] for control in CONTROLS}
    for name in BALLS:
        for control in CONTROLS:
            rs = [runs[name][f"{control} rtol={t:g}"] for t in tolerances]
            cells = []
            for t, r in zip(tolerances, rs, strict=True):
                ratios[control].append(r["error"] / t)
                cells.append(f"{r['error']:.1e} ({r['error'] / t:.2f}), {r['wall'] * 1e3:.0f}, {r['steps']}")
            falls = falls_at_every_tightening([r["error"] for r in rs])
            ref = sweep_refs[name]
            lines.append(
                f"| {name} | {control} | {gas_to_bending(name):,.1f} | {ref['apex']:.5f} | "
                f"{ref['uncertainty']:.0e} | " + " | ".join(cells) + f" | {'yes' if falls else 'no'} |"
            )
    lines.append("")
    for control, qs in ratios.items():
        inside = sum(0.3 <= q <= 3.0 for q in qs)
        walls = sum(runs[n][f"{control} rtol={t:g}"]["wall"] for n in BALLS for t in tolerances)
        lines.append(
            f"- {control}: err/rtol {min(qs):.2f}-{max(qs):.2f}, within 0.3-3 in {inside} of {len(qs)} "
            f"runs; wall time of the {len(qs)} runs {walls:.2f} s."
        )
    return lines


def preset_table(runs):
    """Per ball: each preset's error against the reference at its node count, and its wall time."""
    lines = [
        "",
        "The fidelity presets (`ballenv/physics/presets.py`; each at its own node count, its error against "
        "the converged run at that node count):",
        "",
        "| ball | "
        + " | ".join(
            f"{p} (N = {v['n_nodes']}, rtol {v['rtol']:g}): err, wall ms" for p, v in FIDELITY_PRESETS.items()
        )
        + " |",
        "|---|" + "---:|" * len(FIDELITY_PRESETS),
    ]
    for name in BALLS:
        cells = [f"{runs[name][p]['error']:.1e}, {runs[name][p]['wall'] * 1e3:.0f}" for p in FIDELITY_PRESETS]
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    worst = {p: max(runs[n][p]["error"] for n in BALLS) for p in FIDELITY_PRESETS}
    lines += ["", "| preset | stated bound | worst over the balls | held |", "|---|---:|---:|---|"]
    for p, v in FIDELITY_PRESETS.items():
        bound = v["apex_error_bound"]
        lines.append(f"| {p} | {bound:.1%} | {worst[p]:.2%} | {'yes' if worst[p] <= bound else 'NO'} |")
    return lines


def node_table(refs):
    """Per ball: the converged first apex at each node count and its change from the next coarser."""
    counts = [str(n) for n in REFERENCE_NODES]
    lines = [
        "",
        "What the node count costs in accuracy (the polygon's own error, which no step control removes): "
        "the converged first apex per node count, and its change from the next coarser count.",
        "",
        "| ball | " + " | ".join(f"N = {n}: apex (m), change" for n in counts) + " |",
        "|---|" + "---:|" * len(counts),
    ]
    for name in BALLS:
        apexes = [refs[n][name]["apex"] for n in counts]
        cells = [f"{apexes[0]:.5f}"]
        cells += [f"{b:.5f}, {b / a - 1:+.2%}" for a, b in zip(apexes, apexes[1:], strict=False)]
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return lines


def resting_walls():
    """(wall s of ``REST_SECONDS`` of the env's ball (damping 20 1/s) resting on its floor with Scene's
    default step, with the former default's fixed 0.1 ms steps)."""
    rest = dataclasses.replace(ball_scene("env", SWEEP_NODES), grounds=(Ground(friction=0.5),), damping=20.0)
    x0 = resting_nodes(rest)
    walls = []
    for numerics in ({}, FORMER_DEFAULT):
        scene = dataclasses.replace(rest, **numerics)
        simulate(scene, 1e-3, x0=x0)  # numba warm
        walls.append(simulate(scene, REST_SECONDS, x0=x0).stats.wall_time)
    return tuple(walls)


def resting_nodes(scene):
    """The ring of ``scene`` moved down to rest its lowest node on the floor (nodes, m)."""
    x = initial_state(scene)[0][0]
    x[:, 1] -= x[:, 1].min()
    return x


def default_table(runs):
    """Scene's default step (adaptive, rtol 0.01) against the former default (fixed 0.1 ms steps)."""
    at_rest, at_rest_former = resting_walls()
    lines = [
        "",
        '`Scene`\'s default step (adaptive, largest step 10 ms, `rtol` 0.01, `contact_error` "impulse", '
        "rho_inf 0.9; the sweep's impulse rtol=0.01 run) against the former default (fixed 0.1 ms steps), "
        f"N = {SWEEP_NODES}:",
        "",
        "| ball | default: err, wall ms, steps | fixed 0.1 ms: err, wall ms, steps |",
        "|---|---:|---:|",
    ]
    for name in BALLS:
        cells = [runs[name][k] for k in (DEFAULT_RUN, "former default")]
        lines.append(
            f"| {name} | "
            + " | ".join(f"{r['error']:.1e}, {r['wall'] * 1e3:.0f}, {r['steps']}" for r in cells)
            + " |"
        )
    lines += [
        "",
        f"The env's ball at rest on its floor (friction 0.5) for {REST_SECONDS:g} s: {at_rest:.2f} s of wall "
        f"time with the default step, {at_rest_former:.1f} s with fixed 0.1 ms steps.",
    ]
    return lines


def plot(runs, tolerances, path):
    """Work-precision per ball (left) and achieved error over rtol (right)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax_wp, ax_ratio) = plt.subplots(1, 2, figsize=(11, 4.2))
    for k, name in enumerate(BALLS):
        for control, style in zip(CONTROLS, ("o--", "s-"), strict=True):
            rs = [runs[name][f"{control} rtol={t:g}"] for t in tolerances]
            label = f"{name}, {control}"
            color = f"C{k}"
            walls, errors = [r["wall"] * 1e3 for r in rs], [r["error"] for r in rs]
            ax_wp.loglog(walls, errors, style, color=color, label=label)
            ratios = [r["error"] / t for r, t in zip(rs, tolerances, strict=True)]
            ax_ratio.loglog(tolerances, ratios, style, color=color, label=label)
    ax_wp.set(xlabel="wall time (ms)", ylabel="first-apex error (relative)", title="work-precision")
    ax_ratio.axhspan(0.3, 3.0, color="0.9", label="0.3-3x")
    ax_ratio.set(xlabel="requested rtol", ylabel="achieved error / rtol", title="tolerance proportionality")
    ax_ratio.legend(fontsize=6, ncol=2)
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
        write_text(RESULTS / "accuracy.md", text)
        plot(runs, tolerances, RESULTS / "accuracy.png")


if __name__ == "__main__":
    main()
