"""Where the error and the cost of ``Scene.rtol`` come from on the six balls of ``ball_family.py``.

    python benchmarks/accuracy_sources.py   # writes benchmarks/results/accuracy_sources.md (~3 min)

For each ball and tolerance: the first-apex error with both step criteria (the local error estimate
and the contact bound ``rtol M sqrt(g R)``, with the touchdown location) and without the estimate
(``atol`` = 1 m, which no step's estimate reaches); the accepted steps in contact (a node on the
ground at the step's end), in flight before the first apex and after it; the rejected steps by
criterion; the ring's contact events (touchdowns and lift-offs) before the first apex and the nodes'
arrivals on the ground (a node's reaction switching on between two steps), against the reference's
events (``ball_family.reference_scene``). Errors against the cached references of ``accuracy.py``.
All runs: generalized-alpha, ``rho_infinity`` = 0.9, adaptive, largest step 10 ms, N = 64.
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import pathlib  # noqa: E402

import numpy as np  # noqa: E402
from accuracy import NUMERICS, TOLERANCES, references  # noqa: E402
from ball_family import BALLS, T_END, ball_scene, first_apex, reference_scene  # noqa: E402

from ballenv.files import write_text  # noqa: E402
from ballenv.physics import simulate  # noqa: E402

RESULTS = pathlib.Path(__file__).parent / "results"


def contact_events(traj, t_apex):
    """Touchdowns and lift-offs of the ring before ``t_apex`` (s)."""
    return sum(1 for t, _, kind in traj.events if kind != "apex" and t <= t_apex)


def run(name, scene, reference):
    """Error, steps by phase, rejections and contact events of one run of ball ``name``."""
    apex, traj = first_apex(name, scene)
    t_apex = traj.apexes()[0, 0]
    on_ground = np.abs(traj.contact_force[:, 0]).sum(axis=2) > 0.0  # (records, nodes)
    in_contact = on_ground.any(axis=1)
    before = traj.t <= t_apex
    return {
        "error": abs(apex - reference) / reference,
        "contact": int((in_contact & before).sum()),
        "flight": int((~in_contact & before).sum()),
        "after": int((~before).sum()),
        "rejected": (traj.stats.rejections["error"], traj.stats.rejections["impulse"]),
        "events": contact_events(traj, t_apex),
        "arrivals": int((~on_ground[:-1] & on_ground[1:]).sum()),
    }


def reference_events(name):
    """Contact events before the first apex of the reference run (one record per 1 ms)."""
    traj = simulate(reference_scene(name), t_end=T_END.get(name, 1.0), output_dt=1e-3)
    return contact_events(traj, traj.apexes()[0, 0])


def table(refs, progress=print):
    """The markdown rows, one per ball and tolerance."""
    lines = [
        "| ball | rtol | error | error, without the estimate | steps: contact / flight / after apex "
        "| rejected: error / contact | contact events (reference) | node arrivals |",
        "|---|---:|---:|---:|---|---|---:|---:|",
    ]
    for name in BALLS:
        ref = refs["64"][name]["apex"]
        n_ref = reference_events(name)
        for rtol in TOLERANCES:
            both = run(name, ball_scene(name, rtol=rtol, **NUMERICS), ref)
            alone = run(name, ball_scene(name, rtol=rtol, atol=1.0, **NUMERICS), ref)
            lines.append(
                f"| {name} | {rtol:g} | {both['error']:.1e} | {alone['error']:.1e} | "
                f"{both['contact']} / {both['flight']} / {both['after']} | "
                f"{both['rejected'][0]} / {both['rejected'][1]} | {both['events']} ({n_ref}) | "
                f"{both['arrivals']} |"
            )
            progress(lines[-1])
    return lines


def main():
    refs = references()
    text = "\n".join(["# Where the error and the cost of `rtol` come from", "", *table(refs)]) + "\n"
    write_text(RESULTS / "accuracy_sources.md", text)
    print(text)


if __name__ == "__main__":
    main()
