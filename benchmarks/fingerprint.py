"""Bit-for-bit fingerprint of the simulator: did a change of code change any number?

    python benchmarks/fingerprint.py --out before.json    # on the old code
    python benchmarks/fingerprint.py --compare before.json  # on the new code: exit 1 on a difference

Runs the work-precision benchmark's quick scenes (``work_precision.py --quick``: every sweep point,
the presets and the reference of the single bounce, and the flight-convergence runs), the soak's
first ``--scenes`` random scenes (``soak.py``'s generator and seed) and ``--episodes`` env episodes
per action mode (random, extreme and alternating actions, resets included). Each run is reduced to
its accepted and rejected steps, Newton iterations and a SHA-256 of every recorded array (times,
node positions and velocities, pressures, contact forces, events; for episodes every observation,
reward and info value): equal fingerprints mean equal steps, iterations and states to the last bit.
A refactoring that claims to change no number is checked with this.
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import hashlib  # noqa: E402
import json  # noqa: E402
import pathlib  # noqa: E402
import sys  # noqa: E402

import numpy as np  # noqa: E402
from tqdm.auto import tqdm  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

import soak  # noqa: E402
import work_precision as wp  # noqa: E402

from ballenv.envs.inflated_ball import InflatedBallEnv  # noqa: E402
from ballenv.files import write_text  # noqa: E402
from ballenv.physics import SimulationError, simulate  # noqa: E402
from ballenv.physics.build import initial_state  # noqa: E402

INFO_LAYOUT = ("observation_structure",)  # the layout, not a result of the step


def digest(*arrays):
    """SHA-256 (hex) of the bytes of ``arrays`` (float64 / int64, C order)."""
    h = hashlib.sha256()
    for a in arrays:
        a = np.ascontiguousarray(a)
        h.update(str(a.dtype).encode() + str(a.shape).encode())
        h.update(a.tobytes())
    return h.hexdigest()


def run_print(scene, t_end, **kw):
    """Fingerprint of ``simulate(scene, t_end, **kw)`` (a SimulationError's trajectory too)."""
    error = ""
    try:
        traj = simulate(scene, t_end, **kw)
    except SimulationError as exc:
        traj, error = exc.trajectory, str(exc)
    s = traj.stats
    return {
        "steps": s.steps,
        "rejected": s.rejected_steps,
        "newton": s.newton_iterations,
        "rejections": dict(s.rejections),
        "energy_projected": s.energy_projected,
        "energy_removed": float(s.energy_removed).hex(),
        "collision_gain": float(s.collision_gain).hex(),
        "error": error,
        "state": digest(traj.t, traj.x, traj.v, traj.pressure, traj.contact_force, traj.event_table),
    }


def work_precision_prints():
    """The scenes of ``work_precision.py --quick``."""
    out = {}
    name = "bounce"
    t_end = wp.SCENES[name]
    out["reference"] = run_print(wp.configured(wp.base_scene(name), **wp.REFERENCE), t_end)
    for curve, points in wp.curves(name, quick=True).items():
        for point, numerics in points:
            scene = wp.configured(wp.base_scene(name), **numerics)
            out[f"{curve} {point}"] = run_print(scene, t_end, output_dt=wp._record_interval(scene))
    for preset in wp.FIDELITY_PRESETS:
        out[f"preset {preset}"] = run_print(wp.preset_scene(name, preset), t_end)
    for integrator in wp.INTEGRATORS:
        for dt in (1e-4, 5e-5, 2.5e-5, 1.25e-5):
            x, v = wp.flight_state(integrator, dt)
            out[f"flight {integrator} {dt:g}"] = digest(x, v)
    return out


def scene_prints(count, seed=0):
    """The soak's first ``count`` random scenes."""
    rng = np.random.default_rng(seed)
    out = {}
    for k in tqdm(range(count), desc="soak scenes", unit="scene"):
        scene, t_end = soak.random_scene(rng)
        x0, _ = initial_state(scene)
        out[str(k)] = run_print(scene, t_end)
        out[str(k)]["start"] = digest(x0)
    return out


def episode_prints(count, seed=0, steps=250):
    """``count`` env episodes per action mode: every observation, reward and info value."""
    rng = np.random.default_rng(seed)
    out = {}
    for mode in ("pressure", "paddle"):
        env = InflatedBallEnv(action_mode=mode)
        for k in tqdm(range(count), desc=f"{mode} episodes", unit="ep"):
            policy = soak.POLICIES[k % 4]
            obs, info = env.reset(seed=int(rng.integers(2**31)))
            h = hashlib.sha256(obs.tobytes())
            for s in range(steps):
                a = soak.episode_action(policy, rng, s)
                obs, reward, terminated, truncated, info = env.step(np.array([a], dtype=np.float32))
                h.update(obs.tobytes())
                h.update(float(reward).hex().encode())
                kept = sorted((key, repr(v)) for key, v in info.items() if key not in INFO_LAYOUT)
                h.update(repr(kept).encode())
                if terminated or truncated:
                    break
            out[f"{mode} {k}"] = h.hexdigest()
    return out


def fingerprint(scenes, episodes):
    return {
        "work_precision_quick": work_precision_prints(),
        "soak_scenes": scene_prints(scenes),
        "env_episodes": episode_prints(episodes),
    }


def differences(old, new, path=""):
    """Paths at which two fingerprints differ."""
    if isinstance(old, dict) and isinstance(new, dict):
        out = []
        for key in sorted(set(old) | set(new)):
            out += differences(old.get(key), new.get(key), f"{path}/{key}")
        return out
    return [] if old == new else [f"{path}: {old!r} -> {new!r}"]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", type=int, default=200, help="soak scenes (default 200)")
    parser.add_argument("--episodes", type=int, default=20, help="env episodes per action mode (default 20)")
    parser.add_argument("--out", type=pathlib.Path, help="write the fingerprint (JSON) here")
    parser.add_argument("--compare", type=pathlib.Path, help="compare with a fingerprint written before")
    args = parser.parse_args(argv)
    prints = fingerprint(args.scenes, args.episodes)
    if args.out:
        write_text(args.out, json.dumps(prints, indent=1, sort_keys=True))
        print(f"wrote {args.out}")
    if args.compare:
        diff = differences(json.loads(args.compare.read_text()), json.loads(json.dumps(prints)))
        runs = sum(len(v) for v in prints.values())
        if diff:
            print(f"{len(diff)} differences in {runs} runs:")
            print("\n".join(diff[:50]))
            return 1
        print(f"identical: {runs} runs (steps, Newton iterations, rejections and every state bit)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
