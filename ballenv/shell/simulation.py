"""``simulate(scene, t_end)``: shells under their gas, gravity, damping, grounds and friction, advanced
by implicit steps (implicit.py), recorded in a :class:`Trajectory` (SI units).

Each shell starts from its inflated equilibrium (equilibrium.py) centred at its ``position``, or
from ``x0``, with the velocity ``velocity + angular_velocity x (x - centre)`` or ``v0``. All shells
take the same steps; shells that may touch take them jointly (groups.py, joint.py). Step control: a
step whose Newton iteration fails for any shell is rejected (never accepted) and retried with half
the step; below ``dt_min`` ``simulate`` raises :class:`SimulationError`. With ``adaptive``, the
local error estimate of the ring's integrators (``ballenv.physics.step.integrator``), ``e_i = c h^2
(a1_i - w a0_i)`` (m; generalized-alpha ``c = beta - 1/6``, ``w = 1``; backward Euler ``c = 1/2``,
``w = 0``), must have an RMS over each shell's vertices of at most ``rtol R``: a larger one rejects
the step, and the next step is ``h min(1.25, max(0.2, 0.9 (rtol R / e)^q))`` (``q`` 1/3 or 1/2), at
most ``dt``. Without it, steps are ``dt``, and a halved step doubles back after each accepted step.
Records are every accepted step, or, with ``output_dt``, at its multiples, interpolated inside the
steps (cubic Hermite positions and their derivative; contact forces linearly), which never changes
the steps.
Each shell's energy is held to its value at the start plus the work moving grounds have done on it
(budget.py): an accepted step's small excess is taken from its deformation's (or spin's) kinetic
energy, a larger one rejects the step. Moving grounds (touch/motion.py) are placed at each trial
step's end, and the step is shortened so that no plane advances more than half its distance to the
nearest vertex; turning drums (touch/turning.py) are turned through each trial step. Every vertex
must start above every ground, on its side of every drum (at t = 0) and outside every other shell
(``ValueError`` otherwise).
"""

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..physics.base.record_ref import RecordRef
from ..physics.step import integrator
from .rest.equilibrium import equilibrium
from .scene import Scene
from .skin.gas import gauge_pressure, volume
from .skin.mesh import icosphere, winding_numbers
from .skin.model import build_model
from .step import budget, events, groups, implicit, stepdata
from .touch import drum, ground, motion, turning

F64 = NDArray[np.float64]
SHRINK = 0.2  # smallest factor of an adaptive step's change


class SimulationError(RuntimeError):
    """The step was halved below ``Scene.dt_min`` without an accepted step."""


@dataclass
class SimulationStats:
    """steps: accepted; rejections; newton_iterations, cg_iterations and envelope_solves (the CG
    fallback) summed over shells (a joint step of shells in contact counts once) and accepted steps;
    wall_time (s) of the stepping."""

    steps: int = 0
    rejections: int = 0
    newton_iterations: int = 0
    cg_iterations: int = 0
    envelope_solves: int = 0
    wall_time: float = 0.0


@dataclass
class Trajectory:
    """t (T,) s; x, v (T, shells, V, 3) m, m/s; contact_force (T, shells, V, 3) N, the grounds'
    barrier and friction force plus the contact barrier's between shells and within one (contact.py);
    pressure (T, shells) Pa gauge; events: ``(t s, shell, kind,
    centre-of-mass height m)`` with kind "apex", "touchdown" or "liftoff"; stats; boundary_work
    (T, shells) J: the work credited to each shell's energy budget for the moving grounds since
    t = 0 (budget.boundary_work: an upper bound of their work, the step dissipating the rest; 0 on
    fixed grounds), so that its energy never exceeds its start energy plus this."""

    t: F64
    x: F64
    v: F64
    contact_force: F64
    pressure: F64
    events: list[tuple[float, int, str, float]]
    stats: SimulationStats
    scene: Scene = field(repr=False)
    boundary_work: F64 = field(default_factory=lambda: np.zeros((0, 0)), repr=False)

    def apexes(self, shell: int = 0) -> F64:
        """(k, 2): (t s, centre-of-mass height m) of each apex of ``shell``, located in its step."""
        rows = [(t, z) for t, k, kind, z in self.events if k == shell and kind == "apex"]
        return np.array(rows, dtype=np.float64).reshape(-1, 2)


def build(scene: Scene) -> tuple[implicit.Integrator, list[stepdata.ShellStep]]:
    """The integrator and each shell's step data."""
    method = implicit.make_integrator(
        scene.integrator, scene.rho_infinity, scene.newton_tol, scene.newton_max_iter, scene.dt
    )
    g = np.array(scene.gravity_vector)
    normals = np.array([gr.normal for gr in scene.grounds], dtype=np.float64).reshape(-1, 3)
    heights = np.array([gr.height for gr in scene.grounds], dtype=np.float64)
    mu = np.array([gr.friction for gr in scene.grounds], dtype=np.float64)
    slide = np.zeros((len(scene.grounds), 3))
    steps: list[stepdata.ShellStep] = []
    for shell in scene.shells:
        model = build_model(shell, scene.gas_exponent, scene.atmospheric_pressure)
        kappa = scene.contact_stiffness or shell.youngs_modulus * shell.thickness
        contact = (scene.contact_distance, kappa, scene.friction_velocity)
        drums = None
        if scene.drums:
            drums = drum.make_drums(scene.drums, len(model.rest), steps[0].drums if steps else None)
        grounds = (normals, heights, mu, slide)
        steps.append(stepdata.make_step(model, g, grounds, contact, scene.damping, drums))
    return method, steps


def initial_states(scene: Scene, x0: ArrayLike | None, v0: ArrayLike | None) -> tuple[F64, F64]:
    """Positions and velocities (shells, V, 3) at t = 0 (module doc)."""
    n = [s.n_vertices for s in scene.shells]
    if len(set(n)) != 1:
        raise ValueError(f"Scene.shells must all have the same subdivisions (vertex counts {n})")
    shape = (len(n), n[0], 3)
    xs, vs = np.zeros(shape), np.zeros(shape)
    if x0 is not None:
        xs[:] = np.asarray(x0, dtype=np.float64).reshape(shape)
    for k, shell in enumerate(scene.shells):
        model = build_model(shell, scene.gas_exponent, scene.atmospheric_pressure)
        if x0 is None:
            x = equilibrium(
                shell, gas_exponent=scene.gas_exponent, atmospheric_pressure=scene.atmospheric_pressure
            ).x
            xs[k] = x - events.centre(model.mass, x) + np.array(shell.position)
        spin = np.cross(np.array(shell.angular_velocity), xs[k] - events.centre(model.mass, xs[k]))
        vs[k] = np.array(shell.velocity) + spin
    if v0 is not None:
        vs[:] = np.asarray(v0, dtype=np.float64).reshape(shape)
    if not (np.all(np.isfinite(xs)) and np.all(np.isfinite(vs))):
        raise ValueError(f"x0 and v0 must be finite arrays of shape {shape} (m, m/s)")
    _check_apart(scene, xs, x0 is not None)
    _check_drums(scene, xs, x0 is not None)
    for k, shell in enumerate(scene.shells):
        for g, gr in enumerate(scene.grounds):
            gap = float((xs[k] @ np.array(gr.normal)).min()) - gr.height
            if gap <= 0.0:
                name = "x0" if x0 is not None else f"Scene.shells[{k}].position"
                value = "given" if x0 is not None else shell.position
                raise ValueError(
                    f"{name} = {value} is out of range: shell {k} starts {-gap:.4g} m through "
                    f"grounds[{g}]; every vertex must start above every ground"
                )
    return xs, vs


def _check_drums(scene: Scene, xs: F64, given: bool) -> None:
    """``ValueError`` if a vertex starts on the wrong side of a drum (at t = 0)."""
    for k, shell in enumerate(scene.shells):
        for j, dr in enumerate(scene.drums):
            axis, r = np.array(dr.axis), xs[k] - np.array(dr.centre)
            rho = np.linalg.norm(r - np.outer(r @ axis, axis), axis=1)
            gap = float((dr.radius - rho if dr.inside else rho - dr.radius).min())
            if gap <= 0.0:
                name = "x0" if given else f"Scene.shells[{k}].position"
                value = "given" if given else shell.position
                side, wrong = ("inside", "outside") if dr.inside else ("outside", "inside")
                raise ValueError(
                    f"{name} = {value} is out of range: shell {k} starts {-gap:.4g} m {wrong} "
                    f"drums[{j}]; every vertex must start {side} it"
                )


def _check_apart(scene: Scene, xs: F64, given: bool) -> None:
    """``ValueError`` if a vertex of a shell starts inside another shell (winding number above 1/2)."""
    triangles = icosphere(scene.shells[0].subdivisions).triangles
    centres = xs.mean(axis=1)
    radii = np.linalg.norm(xs - centres[:, None, :], axis=2).max(axis=1)
    for i in range(len(xs)):
        for j in range(len(xs)):
            if i == j or np.linalg.norm(centres[i] - centres[j]) > radii[i] + radii[j]:
                continue
            if winding_numbers(xs[i], xs[j], triangles).max() > 0.5:
                name = "x0" if given else f"Scene.shells[{i}].position"
                value = "given" if given else scene.shells[i].position
                raise ValueError(
                    f"{name} = {value} is out of range: shell {i} starts inside shell {j}; "
                    "shells must start apart"
                )


class Recorder:
    """The records of a run: every accepted step's end, or the multiples of ``output_dt``; none if
    not ``keep`` (a run driven piece by piece that reads its state instead)."""

    def __init__(self, output_dt: float | None, steps: list[stepdata.ShellStep], keep: bool = True) -> None:
        self.output_dt, self.steps, self.keep = output_dt, steps, keep
        self.rows: list[tuple[float, F64, F64, F64, F64, F64]] = []
        self.count = 0

    def add(self, t: float, x: F64, v: F64, force: F64, work: F64) -> None:
        """One record at ``t`` (s) (``work`` (shells,) J: the grounds' work so far)."""
        if not self.keep:
            return
        p = [
            gauge_pressure(st.problem.model, volume(x[k], st.problem.model.triangles))
            for k, st in enumerate(self.steps)
        ]
        self.rows.append((t, x.copy(), v.copy(), force.copy(), np.array(p, dtype=np.float64), work.copy()))
        self.count += 1

    def step(self, t: float, h: float, before: tuple[F64, ...], after: tuple[F64, ...]) -> None:
        """Records for the accepted step ``[t, t + h]`` from its ends' ``(x, v, contact force,
        grounds' work)``."""
        if not self.keep:
            return
        if self.output_dt is None:
            self.add(t + h, *after)
            return
        while self.count * self.output_dt <= t + h * (1.0 + 1e-12):
            s = min(max((self.count * self.output_dt - t) / h, 0.0), 1.0)
            (x0, v0, f0, w0), (x1, v1, f1, w1) = before, after
            s2, s3 = s * s, s * s * s
            x = (
                (2 * s3 - 3 * s2 + 1) * x0
                + (s3 - 2 * s2 + s) * h * v0
                + (3 * s2 - 2 * s3) * x1
                + (s3 - s2) * h * v1
            )
            v = (6 * s2 - 6 * s) * (x0 - x1) / h + (3 * s2 - 4 * s + 1) * v0 + (3 * s2 - 2 * s) * v1
            self.add(self.count * self.output_dt, x, v, (1.0 - s) * f0 + s * f1, (1.0 - s) * w0 + s * w1)

    def arrays(self) -> tuple[F64, F64, F64, F64, F64, F64]:
        """``(t, x, v, contact_force, pressure, boundary_work)`` stacked."""
        return tuple(np.array([row[k] for row in self.rows]) for k in range(6))  # type: ignore[return-value]


class Control(NamedTuple):
    """The integrator's error estimate ``e = c h^2 (a1 - w a0)`` and step exponent ``q`` (module doc)."""

    c: float
    w: float
    q: float


def control(method: implicit.Integrator) -> Control:
    """The step control's constants of ``method``."""
    s = method.solver
    return Control(
        integrator.error_coefficient(s), integrator.error_start_weight(s), integrator.error_exponent(s)
    )


def error_ratio(
    scene: Scene, ctl: Control, steps: list[stepdata.ShellStep], a0: F64, a1: F64, h: float
) -> float:
    """The largest over shells of ``RMS_i |e_i| / (rtol R)`` (module doc)."""
    c, w = ctl.c, ctl.w
    worst = 0.0
    for k, st in enumerate(steps):
        e = c * h * h * (a1[k] - w * a0[k])
        worst = max(worst, float(np.sqrt(np.mean(np.sum(e * e, axis=1)))) / (scene.rtol * st.radius))
    return worst


def try_step(
    method: implicit.Integrator,
    steps: list[RecordRef],
    state: tuple[F64, F64, F64],
    h: float,
    contacts: groups.Contacts | None = None,
) -> list[implicit.StepResult]:
    """Every shell's step of ``h`` (s), or :class:`implicit.StepFailure` (``steps`` the shells'
    ShellSteps by reference); with ``contacts``, shells that may touch step jointly (groups.py)."""
    if contacts is not None:
        return contacts.step(method, state, h)
    x, v, a = state
    return [implicit.step(method, st, x[k], v[k], a[k], h) for k, st in enumerate(steps)]


def next_step(scene: Scene, q: float, h: float, ratio: float) -> float:
    """The step after an accepted one of ``h`` whose error ratio was ``ratio`` (``q``: Control.q)."""
    if not scene.adaptive:
        return min(scene.dt, 2.0 * h)
    grow = (
        integrator.STEP_GROWTH if ratio <= 0.0 else min(integrator.STEP_GROWTH, max(SHRINK, 0.9 * ratio**-q))
    )
    return min(scene.dt, h * grow)


class Run:
    """A run's state between steps: positions, velocities, accelerations and contact forces
    (shells, V, 3), the grounds' work on each shell (J), and what it has recorded (nothing if not
    ``record``); the grounds' motion if one moves (else None), the drums' turning if one turns (else
    None)."""

    def __init__(
        self,
        scene: Scene,
        x0: ArrayLike | None,
        v0: ArrayLike | None,
        output_dt: float | None,
        record: bool = True,
    ):
        self.scene = scene
        self.method, self.steps = build(scene)
        self.refs = [RecordRef(st) for st in self.steps]  # the steps as the compiled step takes them
        touching = len(self.steps) > 1 or scene.self_contact
        dhat = scene.contact_distance
        self.contacts = groups.Contacts(self.steps, dhat, scene.self_contact) if touching else None
        self.x, self.v = initial_states(scene, x0, v0)
        self.a = np.array(
            [implicit.initial_acceleration(st, self.x[k], self.v[k]) for k, st in enumerate(self.steps)]
        )
        self.force = np.zeros_like(self.x)
        self.work = np.zeros(len(self.steps))
        moving = any(gr.moves for gr in scene.grounds)
        st = self.steps[0]
        self.motion = motion.Motion(scene.grounds, st.heights, st.slide, dhat) if moving else None
        turns = st.drums is not None and any(dr.moves for dr in scene.drums)
        self.turning = turning.Turning(scene.drums, st.drums.turn) if turns and st.drums is not None else None
        g = np.array(scene.gravity_vector)
        self.up = -g / np.linalg.norm(g) if np.linalg.norm(g) > 0.0 else np.array([0.0, 0.0, 1.0])
        self.recorder, self.stats = Recorder(output_dt, self.steps, record), SimulationStats()
        self.events: list[tuple[float, int, str, float]] = []
        self.recorder.add(0.0, self.x, self.v, self.force, self.work)
        self.ends = [self.end(k, self.x[k], self.v[k]) for k in range(len(self.steps))]
        self.budget = budget.energies(self.steps, self.x, self.v)
        self.sharing = budget.Sharing(len(self.steps))
        self.control = control(self.method)
        self.t, self.h = 0.0, scene.dt  # s: the time reached and the next step to try
        # called as prepare(t, h) before each step [t, t + h] is tried (steering.py's gas ramps)
        self.preparations: list[Callable[[float, float], None]] = []

    def end(self, k: int, x: F64, v: F64) -> tuple[float, float, float]:
        """Shell ``k``'s events.end at positions ``x`` and velocities ``v``, against the grounds
        where the last step tried left them."""
        st = self.steps[k]
        gap = ground.min_distance(x, st.normals, st.heights)
        if st.drums is not None:
            gap = min(gap, drum.min_distance(x, st.drums))
        return events.end(self.up, st.problem.model.mass, x, v, gap)

    def boundary_work(self, t: float, h: float, results: list[implicit.StepResult]) -> F64:
        """(shells,) J: the work the moving grounds did on each shell in the step ``[t, t + h]``
        just tried (budget.boundary_work); zeros on fixed grounds."""
        if self.motion is None and self.turning is None:
            return np.zeros(len(self.steps))
        heights0 = self.steps[0].heights if self.motion is None else self.motion.offsets(t)
        pairs = zip(self.steps, results, strict=True)
        return np.array([budget.boundary_work(st, heights0, r.x, h) for st, r in pairs])

    def within_budget(self, results: list[implicit.StepResult], work: F64) -> bool:
        """Holds each shell's step end to its energy budget plus ``work`` (J, the grounds' work in
        the step; budget.py; shells stepped jointly share theirs from then on), scaling the
        results' velocities in place; False if the step must be rejected."""
        if self.contacts is not None:
            for group in self.contacts.last_groups:
                self.sharing.join(group)
        for members in self.sharing.sets():
            energy = sum(results[k].energy for k in members)
            limit = sum(self.budget[k] + work[k] for k in members)
            if energy <= limit:
                continue
            steps = [self.steps[k] for k in members]
            xs, vs = [results[k].x for k in members], [results[k].v for k in members]
            if not budget.hold(steps, xs, vs, energy, limit):
                return False
        return True

    def accept(self, t: float, h: float, results: list[implicit.StepResult], work: F64) -> None:
        """Takes the step ``[t, t + h]``: its events, records and work (``work`` (shells,) J the
        grounds', credited to the budgets)."""
        x1, v1 = np.array([r.x for r in results]), np.array([r.v for r in results])
        f1 = np.array([r.contact_force for r in results])
        work1 = self.work + work
        ends = [self.end(k, x1[k], v1[k]) for k in range(len(self.steps))]
        for k, st in enumerate(self.steps):
            self.events += events.detect(t, h, k, self.ends[k], ends[k], st.dhat)
        self.ends = ends
        self.recorder.step(t, h, (self.x, self.v, self.force, self.work), (x1, v1, f1, work1))
        self.stats.steps += 1
        self.stats.newton_iterations += sum(r.iterations for r in results)
        self.stats.cg_iterations += sum(r.cg_iterations for r in results)
        self.stats.envelope_solves += sum(r.envelope_solves for r in results)
        self.x, self.v, self.a, self.force = x1, v1, np.array([r.a for r in results]), f1
        self.budget = [b + w for b, w in zip(self.budget, work, strict=True)]
        self.work = work1

    def advance(self, t_end: float) -> None:
        """Steps from ``self.t`` to ``t_end`` (s), landing on it (module doc's step control); a step
        cut short to land there leaves the next try at least the step it was cut from, so that a run
        advanced piece by piece steps as one advanced at once, apart from the landings."""
        scene, ctl, clock = self.scene, self.control, time.perf_counter()
        t, h = self.t, self.h
        while t < t_end * (1.0 - 1e-12):
            trial = min(h, t_end - t)
            if self.motion is not None:
                trial = self.motion.prepare(self.x, t, trial)
            if self.turning is not None:
                self.turning.prepare(t, trial)
            for prepare in self.preparations:
                prepare(t, trial)
            try:
                results = try_step(self.method, self.refs, (self.x, self.v, self.a), trial, self.contacts)
            except implicit.StepFailure:
                h = self.reject(t, 0.5 * trial, "the step was halved")
                continue
            a1 = np.array([r.a for r in results])
            ratio = error_ratio(scene, ctl, self.steps, self.a, a1, trial) if scene.adaptive else 0.0
            if ratio > 1.0:
                h = self.reject(
                    t, trial * max(SHRINK, 0.9 * ratio**-ctl.q), "the error control shrank the step"
                )
                continue
            work = self.boundary_work(t, trial, results)
            if not self.within_budget(results, work):
                h = self.reject(t, 0.5 * trial, "the step gained energy; halved")
                continue
            self.accept(t, trial, results, work)
            t += trial
            self.t = t
            cut = trial < h and t >= t_end * (1.0 - 1e-12)
            h = (
                max(h, next_step(scene, ctl.q, trial, ratio))
                if cut
                else next_step(scene, ctl.q, trial, ratio)
            )
        self.h = h
        self.stats.wall_time += time.perf_counter() - clock

    def trajectory(self) -> Trajectory:
        """What the run has recorded so far."""
        tt, xx, vv, ff, pp, ww = self.recorder.arrays()
        return Trajectory(tt, xx, vv, ff, pp, sorted(self.events), self.stats, self.scene, ww)

    def reject(self, t: float, h: float, why: str) -> float:
        """Counts a rejected step; returns ``h`` (s), the next try, unless below ``dt_min``."""
        self.stats.rejections += 1
        if h < self.scene.dt_min:
            raise SimulationError(f"{why} below dt_min = {self.scene.dt_min:g} s at t = {t:.6g} s")
        return h


def simulate(
    scene: Scene,
    t_end: float,
    x0: ArrayLike | None = None,
    v0: ArrayLike | None = None,
    output_dt: float | None = None,
) -> Trajectory:
    """Simulate ``scene`` from t = 0 to ``t_end`` (s) (module doc)."""
    if not (isinstance(t_end, (int, float)) and np.isfinite(t_end) and 0.0 < t_end <= 1e6):
        raise ValueError(f"t_end = {t_end!r} is out of range: must be a finite number in (0, 1e6] s")
    if output_dt is not None and not (isinstance(output_dt, (int, float)) and 0.0 < output_dt <= t_end):
        raise ValueError(
            f"output_dt = {output_dt!r} is out of range: must be None or a number in (0, t_end] s"
        )
    run = Run(scene, x0, v0, output_dt)
    run.advance(t_end)
    return run.trajectory()
