"""The 3-D regulation balls (``ballenv.shell.balls``): each wall material's damping fitted on one
rule's drop test, then what the balls predict, and the 3-D ball beside the ring of the same ball.

    python benchmarks/shell_balls.py          # fits; writes benchmarks/results/shell_balls.md
    python benchmarks/shell_balls.py --check  # runs the presets as they are (no fit)
    python benchmarks/shell_balls.py --fine   # also the 642-vertex fits and drops (about 6 minutes more)

For each material, the deformation damping ``c`` (1/s) is the root of ``rebound(c) - target``
(scipy's ``brentq``, to 0.5 1/s: about 0.5 mm of rebound) on the drop test of the ball it is fitted
on, 162 vertices, the presets' numerical settings (``balls.NUMERICS``); the fitted values are
printed as the ``FITTED_DAMPING`` table of ``ballenv/shell/balls.py``. Then, for the presets as
they are: every ball's drop (its rule's, 2 m for the volleyball: rebound as the rule measures it,
restitution, contact time, peak force, wall time); the restitution against pressure (0.6-1.4 times
the ball's) and against impact speed (3-9 m/s, the drop heights ``v^2 / (2 g)``); the ring's ball
of the same name (``ballenv.balls``, its own calibration) dropped from the same height; with
``--fine``, the same drops on 642 vertices with the damping fitted on 162, then with each
material's damping fitted again on 642 (the volleyball with the leather's).
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import math  # noqa: E402
import pathlib  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from scipy.optimize import brentq  # noqa: E402

from ballenv import balls as ring_balls  # noqa: E402
from ballenv.files import write_text  # noqa: E402
from ballenv.shell import balls  # noqa: E402

RESULTS = ROOT / "benchmarks" / "results"
PRESSURE_FACTORS = (0.6, 0.8, 1.0, 1.2, 1.4)
SPEEDS = (3.0, 5.0, 7.0, 9.0)  # m/s
FITTED_ON = {
    "basketball carcass": "basketball",
    "synthetic leather": "football",
    "tennis rubber": "tennis_ball",
}


def fit_damping(ball: balls.Ball) -> float:
    """The damping (1/s) whose drop test rebounds to the middle of the rule's range."""
    test = ball.drop_test
    assert test is not None

    seen: dict[float, float] = {}  # brentq evaluates the bracket's ends again

    def miss(c: float) -> float:
        if c not in seen:
            rebound = balls.drop(ball, damping=c).rebound
            print(f"  {ball.name} ({ball.shell.n_vertices} vertices): c = {c:.2f} 1/s -> {rebound:.4f} m")
            seen[c] = rebound - test.target
        return seen[c]

    low, high = 100.0, 400.0
    while miss(low) < 0.0:
        low *= 0.5
    while miss(high) > 0.0:
        low, high = high, 2.0 * high
    return brentq(miss, low, high, xtol=0.5, rtol=1e-6)


def sphere_contact_time(ball: balls.Ball) -> float:
    """``pi sqrt(M / (2 pi r p))`` (s): half the period of a gas-filled sphere flattening on a floor
    (contact force ``2 pi r p d`` at compression ``d``)."""
    return math.pi * math.sqrt(ball.mass / (2.0 * math.pi * ball.radius * ball.pressure))


def sphere_peak_force(ball: balls.Ball, speed: float) -> float:
    """``v sqrt(2 pi r p M)`` (N): the same sphere's largest force at impact speed ``v``, no loss."""
    return speed * math.sqrt(2.0 * math.pi * ball.radius * ball.pressure * ball.mass)


def timed_drop(ball: balls.Ball, **kwargs) -> tuple[balls.DropResult, float]:
    """A drop and its wall time (s, the whole call: equilibrium, steps, measurement)."""
    clock = time.perf_counter()
    result = balls.drop(ball, **kwargs)
    return result, time.perf_counter() - clock


def drop_table(rows) -> list[str]:
    lines = [
        "| ball | material | c (1/s) | fitted or predicted | p (kPa) | r (cm) | M (g) | h (mm) | drop (m) "
        "| rebound (m) | rule (m) | restitution | contact (ms) | sphere estimate (ms) | peak force (N) "
        "| sphere estimate (N) | steps | wall (s) |",
        "|---|---|---:|---|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for ball, res, wall in rows:
        test = ball.drop_test
        rule = f"{test.rebound[0]:.2f}-{test.rebound[1]:.2f} ({test.measured_to})" if test else "none"
        role = "fitted" if ball.material.fitted_on == ball.name else "predicted"
        lines.append(
            f"| {ball.name} | {ball.material.name} | {ball.damping:.1f} | {role} "
            f"| {ball.pressure / 1e3:.1f} | {100 * ball.radius:.2f} | {1e3 * ball.mass:.1f} "
            f"| {1e3 * ball.shell.thickness:.2f} | {res.drop_height:.2f} | {res.rebound:.3f} | {rule} "
            f"| {res.restitution:.3f} | {1e3 * res.contact_time:.2f} | {1e3 * sphere_contact_time(ball):.2f} "
            f"| {res.peak_force:.0f} | {sphere_peak_force(ball, res.impact_speed):.0f} "
            f"| {res.trajectory.stats.steps} | {wall:.1f} |"
        )
    return lines


def sweep(ball: balls.Ball, label: str, values, run) -> list[float]:
    """Restitution of ``ball`` at each of ``values`` (``run(value)`` -> DropResult)."""
    out = []
    for value in values:
        out.append(run(value).restitution)
        print(f"{ball.name}: {label} {value:g} -> restitution {out[-1]:.3f}", flush=True)
    return out


def sweep_table(head: str, values, table) -> list[str]:
    cols = " | ".join(head.format(v) for v in values)
    lines = [f"| ball | {cols} |", "|---|" + "---:|" * len(values)]
    for name, cors in table.items():
        lines.append(f"| {name} | " + " | ".join(f"{e:.3f}" for e in cors) + " |")
    return lines


def ring_table(rows, ring_rows) -> list[str]:
    lines = [
        "| ball | drop (m) | rebound measured to | shell rebound (m) | ring rebound (m) | shell contact (ms) "
        "| ring contact (ms) | shell peak force (N) | ring peak force (N) | shell c (1/s) | ring c (1/s) |",
        "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for ball, res, _ in rows:
        ring_ball, ring = ring_rows[ball.name]
        lines.append(
            f"| {ball.name} | {res.drop_height:.2f} | {res.measured_to} | {res.rebound:.3f} "
            f"| {ring.rebound:.3f} "
            f"| {1e3 * res.contact_time:.2f} | {1e3 * ring.contact_time:.2f} | {res.peak_force:.0f} "
            f"| {ring.peak_force:.0f} | {ball.damping:.1f} | {ring_ball.damping:.1f} |"
        )
    return lines


def fine_table(rows, fine) -> list[str]:
    lines = [
        "| ball | c on 162 (1/s) | rebound, 162 (m) | rebound, 642, c on 162 (m) | c on 642 (1/s) "
        "| rebound, 642, c on 642 (m) | rule (m) | contact, 162 / 642 (ms) | peak force, 162 / 642 (N) "
        "| wall, 642 (s) |",
        "|---|---:|---:|---:|---:|---:|---|---:|---:|---:|",
    ]
    for ball, res, _ in rows:
        fine_c, refit = fine["fits"][ball.material.name], fine["refit"][ball.name]
        same, wall = fine["same"][ball.name]
        test = ball.drop_test
        rule = f"{test.rebound[0]:.2f}-{test.rebound[1]:.2f}" if test else "none"
        lines.append(
            f"| {ball.name} | {ball.damping:.1f} | {res.rebound:.3f} | {same.rebound:.3f} "
            f"| {fine_c:.1f} | {refit.rebound:.3f} | {rule} | {1e3 * res.contact_time:.2f} / "
            f"{1e3 * refit.contact_time:.2f} | {res.peak_force:.0f} / {refit.peak_force:.0f} | {wall:.1f} |"
        )
    return lines


def fine_runs() -> dict:
    """The 642-vertex drops: with the damping fitted on 162 ("same", with wall times), each
    material's damping fitted on 642 ("fits") and the drops with it ("refit")."""
    made = {name: make(subdivisions=3) for name, make in balls.BALLS.items()}
    same = {name: timed_drop(ball, damping=ball.material.damping[2]) for name, ball in made.items()}
    fits = {mat: fit_damping(made[name]) for mat, name in FITTED_ON.items()}
    refit = {name: balls.drop(ball, damping=fits[ball.material.name]) for name, ball in made.items()}
    return {"same": same, "fits": fits, "refit": refit}


def check_fits(fitted: dict[str, float], subdivisions: int) -> bool:
    """Prints the fitted table; False where the presets' damping on that mesh differs from it."""
    print(f"{subdivisions}: " + ", ".join(f'"{m}": {c:.1f}' for m, c in fitted.items()))
    drift = {m: c for m, c in fitted.items() if abs(c - balls.FITTED_DAMPING[m][subdivisions]) > 0.5}
    if drift:
        print(f"the presets' damping on subdivisions {subdivisions} differs from the fit: {drift}")
    return not drift


def markdown(rows, pressure, speed, ring_rows, fine) -> str:
    rules = "\n".join(
        f"* **{ball.name}**: {ball.rule}."
        + (f" Drop test: {ball.drop_test.rule}." if ball.drop_test else " No drop test: dropped from 2 m.")
        for ball, _, _ in rows
    )
    materials = "\n".join(
        f"* **{m.name}**: E = {m.youngs_modulus / 1e6:g} MPa, nu = {m.poisson_ratio:g}, rho = {m.density:g}"
        f" kg/m^3 ({m.source}); c = {m.damping[2]:.1f} 1/s on 162 vertices, {m.damping[3]:.1f} 1/s on"
        f" 642, fitted on the {m.fitted_on}'s drop test."
        for m in {ball.material.name: ball.material for ball, _, _ in rows}.values()
    )
    fine_part = (
        "\n\n## The same drops on 642 vertices\n\n" + "\n".join(fine_table(rows, fine))
        + "\n\n*Each ball on 642 vertices with its material's damping fitted on 162 vertices, then with"
        " the damping fitted again on 642 (the same rule's test; the volleyball takes the leather's):"
        " how much the fit belongs to the mesh. Contact and peak force on 642: with the damping fitted"
        " on 642. Wall: the drop with the damping of 162.*"
        if fine else ""
    )  # fmt: skip
    return f"""# Regulation balls as 3-D shells

`python benchmarks/shell_balls.py` (about 3 minutes; `--fine`: the 642-vertex fits and drops, about
6 minutes more). Each ball of `ballenv.shell.balls` is an icosphere of 162 vertices with the rule's
radius, mass and pressure (the middle of its ranges); its wall is one of three materials, and each
material has one loss parameter, the deformation damping `c` (`Scene.damping`), fitted on one
ball's drop test to the middle of its rule's range. Everything else below is predicted. Rigid
frictionless floor (the model has no ground compliance), isothermal gas over 101,325 Pa, no air
drag; generalized-alpha (`rho_inf` = 0.9), adaptive steps, `rtol` = 1e-4. One process on a 2-core
machine shared with other jobs (wall times vary by up to 2x).

The materials:

{materials}

## The drops

{chr(10).join(drop_table(rows))}

*Rebound: at the centre of mass's first apex, the height of the ball's lowest vertex (its bottom)
or highest (its top), as the rule measures, from the record nearest the apex. Fitted: the ball the
material's damping was fitted on (its rebound is the fit's target, not a test); predicted: the
other balls. Restitution: `sqrt(rise / drop)` of the centre of mass, its speed out over in. Contact:
first touchdown to last lift-off (a vertex within the barrier's reach, 1 mm). Peak force: the ground
reaction averaged over 0.5 ms windows (the ball's momentum balance). Sphere estimates: a gas-filled
sphere flattening on the floor, contact force `2 pi r p d` at compression `d`: contact
`pi sqrt(M / (2 pi r p))`, peak force `v sqrt(2 pi r p M)` without loss. Wall: the whole `drop`
call (equilibrium, steps, measurement), numba warm.*

The rules:

{rules}

## Restitution against pressure (predicted)

{chr(10).join(sweep_table("{:g} p", PRESSURE_FACTORS, pressure))}

*The same ball (rest radius, wall, damping) pumped to 0.6-1.4 times its pressure (inflated gauge),
dropped from its rule's height (the volleyball from 2 m).*

## Restitution against impact speed (predicted)

{chr(10).join(sweep_table("{:g} m/s", SPEEDS, speed))}

*The ball at its pressure dropped from `v^2 / (2 g)` (0.46, 1.27, 2.50, 4.13 m).*

## The 3-D ball beside the ring of the same ball

{chr(10).join(ring_table(rows, ring_rows))}

*The ring: `ballenv.balls` (a 2-D ring as wide as the ball, N = 64, its own damping fitted on the
same rule's drop test, its "balanced" settings, `ballenv.balls.drop`), dropped from the same height
and measured to the same point of the ball. The two models share the rule, its radius, mass and
pressure; the ring's pressure is its rest-shape gauge pressure, the shell's the inflated ball's.*{fine_part}
"""


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--check", action="store_true", help="run the presets as they are, no fit")
    parser.add_argument("--fine", action="store_true", help="also drop the balls on 642 vertices")
    args = parser.parse_args(argv)
    made = {name: make() for name, make in balls.BALLS.items()}
    balls.drop(made["tennis_ball"], drop_height=0.05)  # compiles
    if not args.check:
        fitted = {mat: fit_damping(made[name]) for mat, name in FITTED_ON.items()}
        if not check_fits(fitted, 2):
            return 1
    rows = [(ball, *timed_drop(ball)) for ball in made.values()]
    for ball, res, wall in rows:
        print(
            f"{ball.name}: rebound {res.rebound:.4f} m, contact {1e3 * res.contact_time:.2f} ms, {wall:.1f} s"
        )
    pressure = {
        name: sweep(
            ball, "pressure x", PRESSURE_FACTORS, lambda f, b=ball: balls.drop(b, pressure=f * b.pressure)
        )
        for name, ball in made.items()
    }
    speed = {
        name: sweep(ball, "speed", SPEEDS, lambda v, b=ball: balls.drop(b, drop_height=v * v / (2 * balls.G)))
        for name, ball in made.items()
    }
    ring_rows = {}
    for name in made:
        ring_ball = ring_balls.BALLS[name]()
        ring_rows[name] = (ring_ball, ring_balls.drop(ring_ball, drop_height=rows_height(rows, name)))
    fine = fine_runs() if args.fine else {}
    if fine and not args.check and not check_fits(fine["fits"], 3):
        return 1
    RESULTS.mkdir(exist_ok=True)
    write_text(RESULTS / "shell_balls.md", markdown(rows, pressure, speed, ring_rows, fine))
    return 0


def rows_height(rows, name: str) -> float:
    """The drop height (m) of ball ``name`` in ``rows``."""
    return next(res.drop_height for ball, res, _ in rows if ball.name == name)


if __name__ == "__main__":
    sys.exit(main())
