"""The scenes: each builds its scenes, simulates them, and measures what the figure claims.

Every function takes ``fidelity`` (a preset of :mod:`ballenv.physics.presets`: "fast" |
"balanced" | "accurate"), ``reduced`` (fewer cases, for the tests) and ``progress`` (a progress
bar per simulation), and returns a :class:`SceneResult`. All parameters are SI (m, Pa, kg/m^3, m/s,
rad, rad/s, s); each scene's are listed in its docstring and in ``SceneResult.parameters``.
"""

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from ballenv.physics import Drum, Ground, Ring, Scene, Simulation, SimulationError, simulate
from ballenv.physics.base.ring import bending_stiffness, inflated_radius, total_mass
from ballenv.physics.step.events import event_list

from ..cluster import collect, run_tasks
from ..physics.presets import with_fidelity
from ..physics.simulation import progress_bar

G = 9.81  # m/s^2


@dataclass
class SceneResult:
    """What a scene ran and measured.

    Attributes:
        name: the scene's name.
        parameters: the scene's inputs (SI units), as documented in its function.
        metrics: the numbers it measured (SI units unless the key says otherwise).
        trajectories: label -> :class:`Trajectory` of each simulation.
        animate: labels of the trajectories the video shows side by side.
    """

    name: str
    parameters: dict
    metrics: dict
    trajectories: dict = field(default_factory=dict)
    animate: tuple = ()


def _run(scene, t_end, fidelity, progress, output_dt=None):
    return simulate(with_fidelity(scene, fidelity), t_end, output_dt=output_dt, progress=progress)


def _drop_height_start(ring_kw, height):
    """Ring keywords with the centre at ``height`` (m)."""
    return {**ring_kw, "position": (0.0, height)}


# ---------------------------------------------------------------- shape measures


def turning_angles(x):
    """Signed turning angle (rad) at each node of the closed polygon ``x`` (N, 2)."""
    edge = np.roll(x, -1, axis=0) - x
    angle = np.arctan2(edge[:, 1], edge[:, 0])
    return np.angle(np.exp(1j * (angle - np.roll(angle, 1))))


def shape_measures(x, normal=(0.0, 1.0)):
    """Measures (dimensionless unless stated) of one ring shape ``x`` (N, 2) on a ground of unit
    ``normal``:

    * ``height`` (m): extent along the normal; ``width`` (m): extent along the surface;
      ``aspect``: width / height.
    * ``curvature_top`` / ``curvature_side``: mean turning angle of the 7 nodes farthest from the
      ground / farthest to the side, over the regular polygon's 2 pi / N; 1 on a circle.
    * ``patch`` (m): length along the surface of the nodes within 1 % of the height of the ground
      (the flattened contact patch).
    """
    n = np.asarray(normal, dtype=float)
    s = np.array([n[1], -n[0]])
    up = x @ n
    along = x @ s
    height = up.max() - up.min()
    width = along.max() - along.min()
    kappa = turning_angles(x) / (2.0 * math.pi / len(x))
    kappa *= np.sign(kappa.sum())
    k = min(7, len(x) // 4)
    top = np.argsort(-up)[:k]
    side = np.argsort(-np.abs(along - along.mean()))[:k]
    near = up < up.min() + 0.01 * height
    return {
        "height": float(height),
        "width": float(width),
        "aspect": float(width / height),
        "curvature_top": float(kappa[top].mean()),
        "curvature_side": float(kappa[side].mean()),
        "patch": float(along[near].max() - along[near].min()),
    }


def rigid_motion(x, v):
    """Centre-of-mass velocity (2,) m/s and spin (rad/s, counter-clockwise) of a ring of equal node
    masses from its nodes ``x, v`` (N, 2)."""
    c = x.mean(axis=0)
    u = v.mean(axis=0)
    r = x - c
    w = v - u
    spin = np.sum(r[:, 0] * w[:, 1] - r[:, 1] * w[:, 0]) / np.sum(r * r)
    return u, float(spin)


def first_event(traj, kind, after=-math.inf, ring=0):
    """Time (s) of the first event ``kind`` of ``ring`` after ``after``, or None."""
    for t, r, k in traj.events:
        if k == kind and r == ring and t > after:
            return t
    return None


# ---------------------------------------------------------------- figure 6


def bounce_vs_pressure(fidelity="balanced", reduced=False, progress=False):
    """Figure 6: first-bounce apex against inflation pressure, for E = 10 and 25 MPa.

    A ring (R = 0.1 m, h = 2 mm, b = 2 cm, rho = 1100 kg/m^3) is released at rest with its centre
    at 1 m above flat frictionless ground, no damping; the apex of its centre after the first
    bounce is located inside the step. Pressures 5, 10, 20, 30, 45, 60 kPa (reduced: 10, 30,
    60 kPa). Claim (the paper): the apex rises with pressure, more for the softer wall.
    """
    moduli = (10e6, 25e6)
    pressures = (10e3, 30e3, 60e3) if reduced else (5e3, 10e3, 20e3, 30e3, 45e3, 60e3)
    ring_kw = {"radius": 0.1, "thickness": 2e-3, "width": 0.02, "density": 1100.0, "position": (0.0, 1.0)}
    apex = {}
    trajectories = {}
    for E in moduli:
        row = []
        for p in pressures:
            scene = Scene(rings=[Ring(youngs_modulus=E, pressure=p, **ring_kw)], grounds=[Ground()])
            traj = _run(scene, 0.95, fidelity, progress)
            row.append(float(traj.apexes()[0, 1]))
            trajectories[f"E={E / 1e6:g}MPa p={p / 1e3:g}kPa"] = traj
        apex[E] = row
    metrics = {
        "pressure_Pa": list(pressures),
        "apex_m": {f"{E / 1e6:g} MPa": apex[E] for E in moduli},
        "apex_rise_m": {f"{E / 1e6:g} MPa": apex[E][-1] - apex[E][0] for E in moduli},
    }
    labels = (f"E=10MPa p={pressures[0] / 1e3:g}kPa", f"E=10MPa p={pressures[-1] / 1e3:g}kPa")
    return SceneResult(
        "bounce-vs-pressure",
        {"youngs_modulus": list(moduli), "pressure": list(pressures), **ring_kw, "drop_height": 1.0},
        metrics,
        trajectories,
        labels,
    )


# ---------------------------------------------------------------- figure 5


def bounce_strip(fidelity="balanced", reduced=False, progress=False):
    """Figure 5: frames of one bounce, 0.015 s apart.

    Ring R = 0.1 m, h = 2 mm, E = 10 MPa, p = 10 kPa (a soft ball, so the flattening shows),
    released at rest with its centre at 0.6 m above flat ground (friction 0.5), no damping.
    Frames every 15 ms from 45 ms before touch-down to 60 ms after lift-off.
    """
    interval = 0.015
    ring = Ring(radius=0.1, thickness=2e-3, youngs_modulus=10e6, pressure=10e3, position=(0.0, 0.6))
    scene = Scene(rings=[ring], grounds=[Ground(friction=0.5)])
    traj = _run(scene, 0.8, fidelity, progress, output_dt=5e-4)
    touch = first_event(traj, "touchdown")
    lift = first_event(traj, "liftoff", after=touch)
    times = np.arange(touch - 3 * interval, lift + 4 * interval + 1e-9, interval)
    times = times[(times >= 0.0) & (times <= traj.t[-1])]
    frames = [int(np.argmin(np.abs(traj.t - t))) for t in times]
    squash = [shape_measures(traj.x[k, 0])["height"] for k in range(len(traj.t))]
    metrics = {
        "touchdown_s": touch,
        "liftoff_s": lift,
        "contact_duration_s": lift - touch,
        "max_compression": 1.0 - min(squash) / squash[0],
        "first_apex_m": float(traj.apexes()[0, 1]),
        "frame_times_s": [float(traj.t[k]) for k in frames],
        "frame_indices": frames,
    }
    params = {**dataclasses.asdict(ring), "friction": 0.5, "frame_interval": interval}
    return SceneResult("bounce-strip", params, metrics, {"bounce": traj}, ("bounce",))


# ---------------------------------------------------------------- figure 7

BASKETBALL = {"radius": 0.12, "thickness": 2e-3, "youngs_modulus": 25e6, "pressure": 30e3}
TENNIS_BALL = {"radius": 0.05, "thickness": 6e-3, "youngs_modulus": 10e6, "pressure": 4e3}


def pressure_bending_number(ring):
    """``p R^3 / (EI / b)`` (dimensionless): gas pressure against wall bending; a pressurised ring
    buckles at 3, so >> 3 is gas-dominated (a basketball), <~ 3 bending-dominated (a tennis ball)."""
    return ring.pressure * ring.radius**3 * ring.width / bending_stiffness(ring)


def deformation(fidelity="balanced", reduced=False, progress=False, speed=3.0):
    """Figure 7: a basketball and a tennis ball hit the ground at the same speed.

    Basketball-like ring: R = 0.12 m, h = 2 mm, E = 25 MPa, p = 30 kPa (p R^3 / EI ~ 3100 >> 3:
    the gas carries the load). Tennis-ball-like ring: R = 5 cm, h = 6 mm, E = 10 MPa, p = 4 kPa
    (p R^3 / EI ~ 2.8 <~ 3: the wall's bending carries it). Both b = 2 cm, rho = 1100 kg/m^3,
    start 5 mm above frictionless ground moving down at ``speed`` (3 m/s), gravity on, no damping.
    Measured at the largest compression (smallest height): aspect ratio width / height, the wall's
    curvature at the top and at the sides relative to a circle's, and the contact patch. Claim
    (Stronge, the paper): the basketball flattens locally (a flat patch; the free wall stays a
    circle, top and side curvatures ~1, little aspect change) and the tennis ball deforms globally
    into an oval (aspect well above 1, flattened top, sharper sides).
    """
    cases = {"basketball": BASKETBALL, "tennis ball": TENNIS_BALL}
    metrics = {}
    trajectories = {}
    for label, kw in cases.items():
        probe = Ring(width=0.02, density=1100.0, **kw)
        r = inflated_radius(probe)
        ring = dataclasses.replace(probe, position=(0.0, r + 0.005), velocity=(0.0, -speed))
        traj = _run(Scene(rings=[ring], grounds=[Ground()]), 0.08, fidelity, progress, output_dt=2e-4)
        heights = [shape_measures(x)["height"] for x in traj.x[:, 0]]
        k = int(np.argmin(heights))
        m = shape_measures(traj.x[k, 0])
        rest = shape_measures(traj.x[0, 0])
        metrics[label] = {
            "p_R3_over_EI": pressure_bending_number(ring),
            "time_of_max_compression_s": float(traj.t[k]),
            "compression": 1.0 - m["height"] / rest["height"],
            "aspect": m["aspect"],
            "aspect_change": m["aspect"] - rest["aspect"],
            "curvature_top": m["curvature_top"],
            "curvature_side": m["curvature_side"],
            "curvature_side_over_top": m["curvature_side"] / m["curvature_top"],
            "patch_over_width": m["patch"] / m["width"],
            "frame_index": k,
        }
        trajectories[label] = traj
    params = {label: {**kw, "width": 0.02, "density": 1100.0} for label, kw in cases.items()}
    params["impact_speed"] = speed
    return SceneResult("deformation", params, metrics, trajectories, tuple(cases))


# ---------------------------------------------------------------- figure 8


def rolling(fidelity="balanced", reduced=False, progress=False):
    """Figure 8: unpressurised rings rolling down a slope, E = 2, 4, 6, 8 MPa (after Raux et al.).

    Ring R = 0.1 m, h = 5 mm, b = 2 cm, rho = 1100 kg/m^3, no gas; slope 0.15 rad with friction
    0.8; deformation damping 20 1/s (rolling is not damped); released at rest 3 mm above the slope
    as a circle, it sags under its own weight and rolls. The elasto-gravity number
    ``rho g h R^3 / (EI / b) = 12 rho g R^3 / (E h^2)`` is 2.6, 1.3, 0.86, 0.65. Measured: the rolling
    shape's height (across the slope) over the rest diameter, averaged over the last 0.5 s of
    2 s (reduced: of 1.5 s), and the rolling speed then. Claim (Raux et al., the paper): the height
    grows with E.
    """
    moduli = (2e6, 4e6, 6e6, 8e6)
    slope, radius, thickness, t_end = 0.15, 0.1, 5e-3, 1.5 if reduced else 2.0
    n = np.array([-math.sin(slope), math.cos(slope)])
    tangent = np.array([math.cos(slope), math.sin(slope)])
    heights, speeds, numbers = [], [], []
    trajectories = {}
    for E in moduli:
        centre = tuple((radius + 0.003) * n)
        ring = Ring(radius=radius, thickness=thickness, youngs_modulus=E, pressure=None, position=centre)
        scene = Scene(rings=[ring], grounds=[Ground(angle=slope, friction=0.8)], damping=20.0)
        traj = _run(scene, t_end, fidelity, progress, output_dt=5e-3)
        last = traj.t > t_end - 0.5
        up = traj.x[:, 0] @ n
        heights.append(float(np.mean(up.max(axis=1)[last] - up.min(axis=1)[last]) / (2 * radius)))
        com = traj.centre_of_mass()[:, 0] @ tangent
        speeds.append(float(-np.polyfit(traj.t[last], com[last], 1)[0]))
        numbers.append(12 * ring.density * G * radius**3 / (E * thickness**2))
        trajectories[f"E={E / 1e6:g}MPa"] = traj
    metrics = {
        "youngs_modulus_Pa": list(moduli),
        "height_over_diameter": heights,
        "rolling_speed_m_per_s": speeds,
        "elastogravity_number": numbers,
    }
    params = {
        "youngs_modulus": list(moduli),
        "radius": radius,
        "thickness": thickness,
        "width": 0.02,
        "density": 1100.0,
        "slope": slope,
        "friction": 0.8,
        "damping": 20.0,
        "t_end": t_end,
    }
    return SceneResult("rolling", params, metrics, trajectories, tuple(trajectories))


# ---------------------------------------------------------------- variable inflation


def _advance_to_flight_apex(sim, t_end, interval, progress):
    """Advance ``sim`` in steps of ``interval`` (s) until the first apex after a lift-off (True) or
    ``t_end`` (s) (False), with a progress bar if ``progress``; raises SimulationError if the run
    fails."""
    bar = progress_bar(t_end, sim.t) if progress else None
    try:
        return _steps_to_flight_apex(sim, t_end, interval, bar)
    finally:
        if bar is not None:
            bar.close()


def _steps_to_flight_apex(sim, t_end, interval, bar):
    seen = sim.event_count
    lifted = False
    while sim.t < t_end - 1e-12:
        if not sim.advance(min(t_end, (round(sim.t / interval) + 1) * interval)):
            raise SimulationError(sim.failure, sim.trajectory())
        if bar is not None:
            bar.update(sim.t - bar.n)
        for _, _, kind in event_list(sim.event_rows(seen)):
            lifted = lifted or kind == "liftoff"
            if kind == "apex" and lifted:
                return True
        seen = sim.event_count
    return False


def pumped_bounces(schedule, fidelity, progress, ring_kw, damping, output_dt=1e-3):
    """A ring bounced on flat ground whose gas is set, at each apex in flight, to the next amount of
    ``schedule`` (gauge pressures at rest, Pa) with :meth:`Simulation.set_rest_pressure`, as the
    env's pump does: one continuous run. Each stage lasts until its first apex after a lift-off, at
    most two free-fall times from its start height plus 0.15 s (the last stage: all of that).
    Returns its :class:`Trajectory` (the first stage's scene) and the switch times (s)."""
    scene = with_fidelity(
        Scene(rings=[Ring(pressure=schedule[0], **ring_kw)], grounds=[Ground(friction=0.5)], damping=damping),
        fidelity,
    )
    sim = Simulation(scene, output_dt=output_dt)
    switches = []
    for k, pressure in enumerate(schedule):
        if k and pressure != schedule[k - 1]:
            sim.set_rest_pressure(0, pressure)
        if k:
            switches.append(sim.t)
        height = float(sim.state.x[0, :, 1].mean())
        t_stage = sim.t + 2.0 * math.sqrt(2.0 * max(height, 0.05) / G) + 0.15
        if k == len(schedule) - 1:
            if not sim.advance(t_stage, progress):
                raise SimulationError(sim.failure, sim.trajectory())
        elif not _advance_to_flight_apex(sim, t_stage, output_dt, progress):
            break
    return sim.trajectory(), switches


def variable_inflation(fidelity="balanced", reduced=False, progress=False):
    """A variable-inflation ball: gas pumped in at each apex, against the same ball left alone.

    Ring R = 0.1 m, h = 2 mm, E = 10 MPa, b = 2 cm, rho = 1100 kg/m^3, released at rest with its
    centre at 1 m over flat ground (friction 0.5), deformation damping 20 1/s (the env's). The
    pumped ball's gas is set at its successive apexes to 10, 20, 30, 45, 60 kPa gauge at rest
    (reduced: 10, 30, 60 kPa); the other keeps 10 kPa. In contact the gas law
    ``(p + p_atm) A = const`` raises the pressure as the ball squashes (the pressure trace). Measured:
    each apex of the centre, and its height above the centre of the ball resting on its inflated
    circle (``inflated_radius``, larger with more gas). Claim: more gas, livelier bounces, so the
    pumped ball's bounces rise higher above its resting centre than the unpumped ball's.
    """
    schedule = (10e3, 30e3, 60e3) if reduced else (10e3, 20e3, 30e3, 45e3, 60e3)
    ring_kw = {
        "radius": 0.1,
        "thickness": 2e-3,
        "youngs_modulus": 10e6,
        "width": 0.02,
        "density": 1100.0,
        "position": (0.0, 1.0),
    }
    damping = 20.0
    pumped, switches = pumped_bounces(schedule, fidelity, progress, ring_kw, damping)
    constant, _ = pumped_bounces(schedule[:1] * len(schedule), fidelity, progress, ring_kw, damping)
    n = len(schedule)
    rest = [inflated_radius(Ring(pressure=p, **ring_kw)) for p in schedule]
    pumped_apex = pumped.apexes()[:n, 1]
    constant_apex = constant.apexes()[:n, 1]
    metrics = {
        "schedule_Pa": list(schedule),
        "switch_times_s": switches,
        "rest_centre_height_m": rest,
        "pumped_apex_m": pumped_apex.tolist(),
        "constant_apex_m": constant_apex.tolist(),
        "pumped_rise_above_rest_m": (pumped_apex - np.array(rest[: len(pumped_apex)])).tolist(),
        "constant_rise_above_rest_m": (constant_apex - rest[0]).tolist(),
        "peak_pressure_Pa": float(pumped.pressure.max()),
    }
    params = {**ring_kw, "schedule": list(schedule), "damping": damping, "friction": 0.5}
    return SceneResult(
        "variable-inflation",
        params,
        metrics,
        {"pumped": pumped, "constant": constant},
        ("pumped", "constant"),
    )


# ---------------------------------------------------------------- slope with spin


def slope_spin(fidelity="balanced", reduced=False, progress=False):
    """A ball bouncing on a 0.3 rad slope with back-spin, no spin and top-spin.

    Ring R = 0.1 m, h = 2 mm, E = 10 MPa, p = 30 kPa, dropped from rest (centre 0.5 m above the
    slope's point below it) with spin -30, 0, +30 rad/s (counter-clockwise positive; the slope
    rises to the right, so downhill is -x and +30 rad/s is top-spin for the downhill motion);
    friction 0.5, no damping. Measured after the first lift-off: the centre's velocity along the
    slope (downhill positive) and off it, and the spin. Claim: friction at the contact trades
    spin for downhill speed, so top-spin leaves faster downhill than back-spin, and the spin moves
    toward rolling.
    """
    slope, mu = 0.3, 0.5
    spins = (-30.0, 30.0) if reduced else (-30.0, 0.0, 30.0)
    n = np.array([-math.sin(slope), math.cos(slope)])
    downhill = -np.array([math.cos(slope), math.sin(slope)])
    rows = []
    trajectories = {}
    for w in spins:
        ring = Ring(
            radius=0.1,
            thickness=2e-3,
            youngs_modulus=10e6,
            pressure=30e3,
            position=(0.0, 0.5),
            angular_velocity=w,
        )
        scene = Scene(rings=[ring], grounds=[Ground(angle=slope, friction=mu)])
        traj = _run(scene, 0.55, fidelity, progress, output_dt=1e-3)
        lift = first_event(traj, "liftoff")
        k = min(int(np.searchsorted(traj.t, lift)) + 2, len(traj.t) - 1)
        u, spin = rigid_motion(traj.x[k, 0], traj.v[k, 0])
        u0, spin0 = rigid_motion(traj.x[0, 0], traj.v[0, 0])
        touch = first_event(traj, "touchdown")
        j = max(int(np.searchsorted(traj.t, touch)) - 1, 0)
        ui, _ = rigid_motion(traj.x[j, 0], traj.v[j, 0])
        rows.append(
            {
                "spin_in_rad_per_s": spin0,
                "downhill_in_m_per_s": float(ui @ downhill),
                "normal_in_m_per_s": float(ui @ n),
                "spin_out_rad_per_s": spin,
                "downhill_out_m_per_s": float(u @ downhill),
                "normal_out_m_per_s": float(u @ n),
                "touchdown_s": touch,
                "liftoff_s": lift,
            }
        )
        trajectories[f"spin {w:+g} rad/s"] = traj
    params = {"slope": slope, "friction": mu, "spins": list(spins), "radius": 0.1, "pressure": 30e3}
    return SceneResult("slope-spin", params, {"cases": rows}, trajectories, tuple(trajectories))


# ---------------------------------------------------------------- two balls


def two_balls(fidelity="balanced", reduced=False, progress=False, speed=3.0, offset=0.05):
    """Two balls collide in flight (no gravity, no ground).

    Equal rings R = 0.1 m, h = 2 mm, E = 10 MPa, p = 30 kPa, centres 0.5 m apart along x and
    ``offset`` (5 cm) apart along y, approaching at ``speed`` (3 m/s) each. Measured: total
    momentum before and after (conserved by the equal and opposite collision impulses), the
    normal restitution (relative x velocity after over before) and the spin the oblique contact
    gives each ball.
    """
    kw = {"radius": 0.1, "thickness": 2e-3, "youngs_modulus": 10e6, "pressure": 30e3}
    a = Ring(position=(-0.25, 0.0), velocity=(speed, 0.0), **kw)
    b = Ring(position=(0.25, offset), velocity=(-speed, 0.0), **kw)
    traj = _run(Scene(rings=[a, b], gravity=0.0), 0.25, fidelity, progress, output_dt=1e-3)
    mass = total_mass(a)

    def motion(k):
        return [rigid_motion(traj.x[k, r], traj.v[k, r]) for r in range(2)]

    before, after = motion(0), motion(-1)
    p0 = mass * (before[0][0] + before[1][0])
    p1 = mass * (after[0][0] + after[1][0])
    rel0 = before[1][0][0] - before[0][0][0]
    rel1 = after[1][0][0] - after[0][0][0]
    gap = np.linalg.norm(traj.centre_of_mass()[:, 0] - traj.centre_of_mass()[:, 1], axis=1)
    metrics = {
        "momentum_before_N_s": p0.tolist(),
        "momentum_after_N_s": p1.tolist(),
        "momentum_change_relative": float(np.linalg.norm(p1 - p0) / (2 * mass * speed)),
        "velocity_after_m_per_s": [after[0][0].tolist(), after[1][0].tolist()],
        "spin_after_rad_per_s": [after[0][1], after[1][1]],
        "restitution": float(-rel1 / rel0),
        "closest_centre_distance_m": float(gap.min()),
    }
    params = {**kw, "width": 0.02, "density": 1100.0, "speed": speed, "offset": offset, "gravity": 0.0}
    return SceneResult("two-balls", params, metrics, {"collision": traj}, ("collision",))


# ---------------------------------------------------------------- vibrating plate

PLATE_FREQUENCY = 2.0  # Hz
PLATE_DAMPING = 800.0  # 1/s: a lossy ball, restitution about 0.5 at 2.5 m/s
PLATE_BALL = {"radius": 0.1, "thickness": 2e-3, "youngs_modulus": 10e6, "pressure": 30e3}


def bouncing_ball_thresholds(restitution, n=1):
    """The point-particle bouncing ball on a plate ``A sin(omega t)`` (impacts with restitution
    ``e``, the plate's displacement kept exactly): the orbit that bounces once every ``n`` periods
    takes off at the phase ``phi`` with ``Gamma cos(phi) = n pi (1 - e) / (1 + e)``; it exists from
    ``Gamma_n = n pi (1 - e) / (1 + e)`` and its linearised map (determinant ``e^2``, trace
    ``1 + e^2 - (1 + e)^2 Gamma sin(phi)``) has an eigenvalue -1, period doubling, at
    ``Gamma sin(phi) = 2 (1 + e^2) / (1 + e)^2``, i.e.
    ``Gamma_pd = sqrt(Gamma_n^2 + (2 (1 + e^2) / (1 + e)^2)^2)``. Returns ``(Gamma_n, Gamma_pd)``
    (dimensionless, ``Gamma = A omega^2 / g``)."""
    e = restitution
    exist = n * math.pi * (1.0 - e) / (1.0 + e)
    return exist, math.hypot(exist, 2.0 * (1.0 + e * e) / (1.0 + e) ** 2)


def plate_impact_phase(gamma, restitution, n=1):
    """The stable period-n orbit's impact phase ``phi`` (rad) in (0, pi/2]: ``Gamma cos(phi) = n pi
    (1 - e) / (1 + e)``, ``sin(phi) > 0`` (:func:`bouncing_ball_thresholds`); NaN where it does not exist."""
    c = bouncing_ball_thresholds(restitution, n)[0] / gamma
    return math.acos(c) if c <= 1.0 else math.nan


def drop_restitution(ring_kw, damping, drop, fidelity, progress):
    """The restitution ``e = sqrt(rise / drop)`` of a ring dropped onto a fixed floor with its
    centre ``drop`` (m) above its touching height: ``rise`` (m) the first apex above that height."""
    ring = Ring(**ring_kw)
    touching = inflated_radius(ring)
    scene = Scene(rings=[Ring(**{**ring_kw, "position": (0.0, touching + drop)})], grounds=[Ground()],
                  damping=damping)  # fmt: skip
    traj = _run(scene, 2.0 * math.sqrt(2.0 * drop / G) + 0.1, fidelity, progress)
    return math.sqrt((traj.apexes()[0, 1] - touching) / drop), traj


def late_bounces(traj, t_from, plate, touching):
    """Apex heights (m, of the centre above ``touching``) and impact phases (rad, in [0, 2 pi)) of
    the bounces after ``t_from`` (s) on the oscillating ``plate``: an apex counts when the centre is
    1 mm above where it would touch the plate then; its impact is the next touchdown."""
    omega = 2.0 * math.pi * plate.frequency
    rows = traj.event_table
    apex = traj.apexes()
    touchdowns = np.array([t for t, _, kind in traj.events if kind == "touchdown"])
    heights, phases = [], []
    for t, y in apex[apex[:, 0] >= t_from]:
        if y - touching - plate.amplitude * math.sin(omega * t) < 1e-3:
            continue
        later = touchdowns[touchdowns > t]
        if len(later) and rows is not None:
            heights.append(y - touching)
            phases.append((omega * later[0]) % (2.0 * math.pi))
    return np.array(heights), np.array(phases)


def bounce_period(heights, tolerance=0.05, longest=8):
    """The smallest ``p`` (1 ... ``longest``) with ``heights[k + p]`` within ``tolerance`` times their
    mean of ``heights[k]`` for every ``k`` (a period-p orbit), else 0 (none: chaos, or not settled).
    The default 5 % lets through the scatter of a ring's bounce heights from its wall's ringing
    (about 3 % in the period-1 orbit)."""
    if len(heights) == 0:
        return 0
    tolerance *= float(np.mean(np.abs(heights)))
    for p in range(1, longest + 1):
        if len(heights) > 2 * p and np.all(np.abs(heights[p:] - heights[:-p]) < tolerance):
            return p
    return 0


def period_one_start(gamma, restitution, amplitude, omega):
    """Height (m, of the centre above its touching height on the plate's mean position) and vertical
    velocity (m/s) at t = 0 (plate phase 0) on the point particle's period-1 orbit (takeoff at the
    phase ``phi`` of :func:`plate_impact_phase` with ``u = g T / 2``, ``T = 2 pi / omega``), or
    (``2 cm`` above the plate's top, 0) where it does not exist."""
    phi = plate_impact_phase(gamma, restitution)
    if math.isnan(phi):
        return amplitude + 0.02, 0.0
    period = 2.0 * math.pi / omega
    flown = (2.0 * math.pi - phi) / omega  # s since the takeoff
    up = 0.5 * G * period
    return amplitude * math.sin(phi) + up * flown - 0.5 * G * flown**2, up - G * flown


def plate_bounces(gamma, restitution, fidelity="balanced", progress=False, periods=60, settle=30):
    """A ball started on the point particle's period-1 orbit (:func:`period_one_start`, for the
    restitution ``restitution``) above a floor oscillating at ``A sin(2 pi f t)`` with ``Gamma = A
    (2 pi f)^2 / g``; returns (trajectory, apex heights (m), impact phases (rad)) of the bounces of
    the last ``periods - settle`` periods (:func:`late_bounces`)."""
    f = PLATE_FREQUENCY
    omega = 2.0 * math.pi * f
    amplitude = gamma * G / omega**2
    plate = Ground(amplitude=amplitude, frequency=f)
    touching = inflated_radius(Ring(**PLATE_BALL))
    height, up = period_one_start(gamma, restitution, amplitude, omega)
    ring = Ring(**PLATE_BALL, position=(0.0, touching + height), velocity=(0.0, up))
    scene = Scene(rings=[ring], grounds=[plate], damping=PLATE_DAMPING)
    traj = _run(scene, periods / f, fidelity, progress)
    return (traj, *late_bounces(traj, settle / f, plate, touching))


def plate_point(task):
    """:func:`plate_bounces` of one ``(gamma, restitution, fidelity, reduced)`` point of the
    vibrating plate's grid (a task of :func:`ballenv.cluster.run_tasks`)."""
    gamma, restitution, fidelity, reduced = task
    return plate_bounces(gamma, restitution, fidelity, False, periods=40 if reduced else 60,
                         settle=20 if reduced else 30)  # fmt: skip


def vibrating_plate(fidelity="balanced", reduced=False, progress=False, cluster=None):
    """The bouncing ball on a vibrating plate: a bifurcation diagram against the plate's acceleration.

    A ball (R = 0.1 m, h = 2 mm, E = 10 MPa, p = 30 kPa, damping 800 1/s: a lossy ball) above a
    floor oscillating at ``A sin(2 pi f t)``, f = 2 Hz, for ``Gamma = A (2 pi f)^2 / g`` from 1 to 4
    (step 0.025; reduced: 1.3 and 1.5), started on the point particle's period-1 orbit
    (:func:`period_one_start`; dropped on the plate where there is none): 60 periods, the apex
    heights of the centre (above its touching height on the plate's mean position) and impact
    phases of the bounces of the last 30 periods, their period (:func:`bounce_period`). Against the
    point-particle map (:func:`bouncing_ball_thresholds`) with the restitution ``e`` the ring shows
    when dropped onto a fixed floor from the period-1 bounce height ``g / (8 f^2)`` (m). (Dropped
    from rest instead, the ball falls into a low, sticking period-1 orbit, not the map's.) The
    values of Gamma run as tasks of :func:`ballenv.cluster.run_tasks` on ``cluster`` (None: here,
    one after the other; a value lost with its Ray worker after Ray's retries is a RuntimeError).
    """
    gammas = [1.3, 1.5] if reduced else [round(1.0 + 0.025 * k, 3) for k in range(121)]
    drop = G / (8.0 * PLATE_FREQUENCY**2)
    e, drop_traj = drop_restitution(PLATE_BALL, PLATE_DAMPING, drop, fidelity, progress)
    exist, doubling = bouncing_ball_thresholds(e)
    heights, phases, periods, trajectories = {}, {}, {}, {"drop": drop_traj}
    tasks = [(gamma, e, fidelity, reduced) for gamma in gammas]
    points, lost = collect(
        run_tasks(plate_point, tasks, cluster, desc="Gamma", progress=progress), len(tasks)
    )
    if lost:
        raise RuntimeError(
            f"Gamma {', '.join(str(gammas[t.index]) for t in lost)} lost with their Ray worker"
        )
    for gamma, (traj, h, phi) in zip(gammas, points, strict=True):
        heights[gamma], phases[gamma] = h.tolist(), phi.tolist()
        periods[gamma] = bounce_period(h)
        trajectories[f"Gamma {gamma:g}"] = traj
    first = next((g for g in gammas if periods[g] == 1), math.inf)
    onset = next((g for g in gammas if g > first and periods[g] != 1), None)
    metrics = {
        "restitution": e,
        "theory_period_one_from": exist,
        "theory_period_doubling_at": doubling,
        "measured_period_doubling_at": onset,
        "gamma": gammas,
        "period": [periods[g] for g in gammas],
        "apex_heights_m": {str(g): heights[g] for g in gammas},
        "impact_phases_rad": {str(g): phases[g] for g in gammas},
    }
    params = {**PLATE_BALL, "width": 0.02, "density": 1100.0, "damping": PLATE_DAMPING,
              "frequency": PLATE_FREQUENCY, "drop": drop}  # fmt: skip
    return SceneResult("vibrating-plate", params, metrics, trajectories, ())


# ---------------------------------------------------------------- rotating drum

DRUM_RADIUS = 0.15  # m
DRUM_FRICTION = 1.0
DRUM_SPIN_UP = 2.0  # s: the drum's speed grows linearly to its final value over this time
DRUM_DAMPING = 3.0  # 1/s: light, so that it hardly resists the ribbon's tank-treading
RIBBON = {"radius": 0.025, "thickness": 1.5e-3, "width": 0.01, "youngs_modulus": 0.6e6, "density": 1100.0,
          "pressure": None}  # fmt: skip


def principal_aspect(x):
    """Aspect ratio (major over minor axis) of the ring shape ``x`` (N, 2): its extents along the
    principal axes of its nodes' second moment."""
    c = x - x.mean(axis=0)
    _, axes = np.linalg.eigh(c.T @ c)
    p = c @ axes
    extent = p.max(axis=0) - p.min(axis=0)
    return float(extent[1] / extent[0])


def least_curvature(x):
    """The smallest turning angle of the polygon ``x`` (N, 2) over the regular polygon's
    ``2 pi / N``, positive for the ring's own sense of turning: 1 on a circle, 0 on a straight part,
    negative where the wall is concave (a waist between two lobes)."""
    kappa = turning_angles(x)
    return float((kappa * np.sign(kappa.sum())).min() / (2.0 * math.pi / len(x)))


def drum_ribbon(spin, fidelity="balanced", progress=False, t_end=4.0, average=1.0):
    """One ribbon loop in the drum turning up to ``spin`` (rad/s): its trajectory and the means over
    the last ``average`` s (of ``t_end`` s) of its aspect ratio (:func:`principal_aspect`), least
    curvature (:func:`least_curvature`), the polar angle (rad) of its centre from the drum's bottom
    (positive in the drum's sense of turning) and its spin (rad/s)."""
    ring = Ring(**RIBBON, position=(0.0, -DRUM_RADIUS + RIBBON["radius"] + 1e-4))
    drum = Drum(radius=DRUM_RADIUS, friction=DRUM_FRICTION, angular_velocity=spin, spin_up=DRUM_SPIN_UP)
    scene = Scene(rings=[ring], drums=[drum], damping=DRUM_DAMPING)
    traj = _run(scene, t_end, fidelity, progress, output_dt=0.01)
    late = np.nonzero(traj.t > t_end - average - 1e-9)[0]
    shapes = [traj.x[k, 0] for k in late]
    centre = traj.x[late, 0].mean(axis=1)
    spins = [rigid_motion(traj.x[k, 0], traj.v[k, 0])[1] for k in late]
    return traj, {
        "aspect": float(np.mean([principal_aspect(x) for x in shapes])),
        "aspect_range": [
            float(min(principal_aspect(x) for x in shapes)),
            float(max(principal_aspect(x) for x in shapes)),
        ],
        "least_curvature": float(np.mean([least_curvature(x) for x in shapes])),
        "concave_fraction": float(np.mean([least_curvature(x) < 0.0 for x in shapes])),
        "centre_angle_rad": float(np.mean(np.arctan2(centre[:, 0], -centre[:, 1]))),
        "ribbon_spin_rad_per_s": float(np.mean(spins)),
    }


def rotating_drum(fidelity="balanced", reduced=False, progress=False):
    """A soft ribbon loop rolling in a rotating drum: its aspect ratio against the drum's speed.

    The setup of Raux, Reis, Bush & Clanet, "Rolling ribbons" (Phys. Rev. Lett. 105, 044301, 2010):
    an elastic ribbon closed into a loop (about 5 cm across, soft silicone) rolls inside a drum
    turning at a constant speed; at rest gravity makes it an oval, and the faster it rolls the more
    it elongates, up to a two-lobed (peanut) shape. Here, qualitatively and with our own numbers:
    a loop of radius 2.5 cm, h = 1.5 mm, b = 1 cm, E = 0.6 MPa, rho = 1100 kg/m^3, no gas
    (``pressure=None``; gravity-bending number ``rho g h b R^3 / EI`` = 1.5), in a drum of radius
    R_d = 0.15 m (friction 1, damping 3 1/s) spinning up over 2 s to Omega = 0 ... 16 rad/s
    (reduced: 0 and 16), the Froude number ``Fr = Omega^2 R_d / g`` = 0 ... 3.9. Each run is 4 s;
    the aspect ratio (:func:`principal_aspect`), least curvature (negative: a concave waist,
    :func:`least_curvature`), the centre's polar angle from the bottom and the loop's spin are
    averaged over the last second. No number is taken from the paper: their control parameter and
    thresholds are not compared, only the trend.
    """
    spins = [0.0, 16.0] if reduced else [0.0, 2.0, 4.0, 6.0, 8.0, 10.0, 12.0, 14.0, 16.0]
    rows, trajectories = [], {}
    for spin in spins:
        traj, measured = drum_ribbon(spin, fidelity, progress)
        rows.append({"drum_spin_rad_per_s": spin, "froude": spin**2 * DRUM_RADIUS / G, **measured})
        trajectories[f"Omega {spin:g}"] = traj
    metrics = {"rows": rows}
    params = {**RIBBON, "drum_radius": DRUM_RADIUS, "friction": DRUM_FRICTION, "damping": DRUM_DAMPING,
              "spin_up": DRUM_SPIN_UP, "spins": spins}  # fmt: skip
    return SceneResult("rotating-drum", params, metrics, trajectories, ())
