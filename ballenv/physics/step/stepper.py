"""The time step of a scene: one trial step of every ring, its acceptance, and the step size.

:func:`advance` repeats :func:`try_step` until a time, in phases: the step's end (:func:`step_end`:
the step size, the fixed grid, actuation windows and, under error control, a ring's
first touch of a ground: :mod:`ballenv.physics.ground.touchdown`), the actuation the step delivers
(:mod:`ballenv.physics.step.actuation`: its share of a gas ramp or a spread impulse; nothing without them),
the trial step of every ring (collision impulses, Newton's iteration with the contact set,
:mod:`ballenv.physics.step.newton`), the
acceptance tests (Newton failure, self-intersection, energy budget, ring intrusion, contact
impulse), then the bookkeeping of a rejected (:func:`step_outcome`) or an accepted step
(:func:`accept`, the end of a gas ramp, events, records, interpolated within the step at output
times: :mod:`ballenv.physics.step.dense_output`) and the next step size. Counters, clock
and energy columns are the named layouts of :mod:`ballenv.physics.base.layout`.
"""

import math

from ..base.jit import copy_into, kernel
from ..base.layout import (
    CLOCK_BOUNDARY_WORK,
    CLOCK_COLLISION_GAIN,
    CLOCK_ENERGY_REMOVED,
    CLOCK_H,
    CLOCK_T,
    COUNT_BY_REASON,
    COUNT_ENERGY_PROJECTED,
    COUNT_ERROR_REJECTED,
    COUNT_EVENTS,
    COUNT_GRID,
    COUNT_IMPULSE_REJECTED,
    COUNT_NEWTON,
    COUNT_RECORDS,
    COUNT_REJECTED,
    COUNT_REJECTION,
    COUNT_STEPS,
    ENERGY_BUDGET,
    ENERGY_TOTAL,
    GROUND_FRICTION,
    GROUND_KIND,
    GROUND_PLANE,
    REJECT_ENERGY,
    REJECT_INTRUSION,
    REJECT_NEWTON,
    REJECT_SELF_INTERSECTION,
    STATUS_BUFFER_FULL,
    STATUS_DONE,
    STATUS_IMPULSE_AT_DT_MIN,
    STATUS_STEP_TOO_SMALL,
    TALLY_BOUNDARY_WORK,
    TALLY_COLLISION_GAIN,
    TALLY_PROJECTED,
    TALLY_REMOVED,
)
from ..effects.assembly import ring_force
from ..effects.gas import ring_pressure
from ..ground.contact import FREE, frame, rest_on_grounds, surface_velocity
from ..ground.motion import ground_surfaces
from ..ground.touchdown import touchdown_landing
from ..model import CONTACT_NONE
from ..walls.impulses import collision_impulses, collision_step_limit, rings_intrude, self_intersects
from .actuation import drive_landing, drive_step
from .contact_error import arrival_norm, doubling_norm, in_contact
from .dense_output import outputs_within, record_within
from .energy_budget import boundary_work, free_energy, within_energy_budget
from .events import detect_events
from .integrator import arrival_factor, carries_acceleration, error_exponent, time_tolerance
from .joint_newton import contact_transfers, joint_newton, pay_from_relative_motion, rings_met, rings_touch
from .local_error import error_norm
from .newton import COUPLED, PLAIN, newton_ring

CONTINUE = -1  # step_outcome(): retry the step


@kernel
def initial_state_values(model, solver, state, ws):
    """Fill what the stepper carries besides ``x, v``: every ring's energy (its budget = its energy
    now) and, for an integrator that carries it, its start acceleration."""
    for r in range(state.x.shape[0]):
        free_energy(model, r, state.x[r], state.v[r], ws, state.energy[r])
        state.energy[r, ENERGY_BUDGET] = state.energy[r, ENERGY_TOTAL]
    if carries_acceleration(solver):
        initial_acceleration(model, state.x, state.v, state.a, ws)


@kernel
def initial_acceleration(model, x, v, a, ws):
    """``a = F(x, v) / m`` for every ring (the generalized-alpha start value)."""
    for r in range(x.shape[0]):
        ring_force(model, r, x[r], v[r], ws.force)
        for i in range(x.shape[1]):
            for d in range(2):
                a[r, i, d] = ws.force[i, d] / model.node_mass[r]


@kernel(inline="always")
def collision_kicks(model, state, h, ws):
    """With ring collision or self-contact: the velocities after the collision impulses (found on the
    predicted positions ``x0 + h v0``, ``walls/impulses.py``) into ``ws.collision.kicked``, each ring's
    kinetic energy change into ``ws.collision.kinetic_change`` and their net gain (J) tallied;
    returns True. Without either, returns False: the step starts from ``state.v``."""
    cw = ws.collision
    if not (model.collide or model.reject_self_intersection):
        return False
    collision_impulses(
        state.x, state.v, h, model.thickness, model.node_mass, model.collide and not model.ring_barrier,
        model.reject_self_intersection, cw, cw.kicked, cw.kinetic_change, ws.ring_pairs,
    )  # fmt: skip
    created = 0.0
    for r in range(state.x.shape[0]):
        created += cw.kinetic_change[r]
    ws.energy_tally[TALLY_COLLISION_GAIN] = max(0.0, created)
    return True


@kernel(inline="always")
def step_ring(model, solver, r, state, v0, trial, h, ws):
    """Ring ``r``'s trial step and its own acceptance tests (:func:`ring_checks`): returns its Newton
    corrections, or minus the ``REJECT_`` code (Newton failed, the wall crossed itself, the energy
    budget)."""
    copy_into(trial.active[r], state.active[r])
    its = newton_ring(
        model, solver, r, state.x[r], v0[r], state.a[r], h, trial.x[r], trial.v[r], trial.a[r], ws,
        trial.active[r], ws.barrier,
    )  # fmt: skip
    if its < 0:
        return -REJECT_NEWTON
    code = ring_checks(model, r, state, trial, h, ws, 0.0)
    return its if code == 0 else code


@kernel(inline="always")
def ring_checks(model, r, state, trial, h, ws, transfer):
    """Ring ``r``'s acceptance tests of its trial state: 0, or minus the ``REJECT_`` code (the wall
    crossed itself, the energy budget). The energy the step's collision impulses, the contact with
    other rings (``transfer``, J: :func:`step.joint_newton.contact_transfers`) and moving grounds
    (:func:`step.energy_budget.boundary_work`, tallied) gave the ring is credited to its energy budget and
    guard."""
    if model.reject_self_intersection and self_intersects(trial.x[r]):
        return -REJECT_SELF_INTERSECTION
    free_energy(model, r, trial.x[r], trial.v[r], ws, trial.energy[r])
    kicks = model.collide or model.reject_self_intersection
    credit = ws.collision.kinetic_change[r] if kicks else 0.0
    credit += transfer
    work = 0.0
    if model.moving_grounds:
        work = boundary_work(ws.surface_start, ws.surface, trial.active[r], ws.reaction, ws.friction, h)
        work += ws.arrival_work[0]
        ws.energy_tally[TALLY_BOUNDARY_WORK] += work
        credit += work
    trial.energy[r, ENERGY_BUDGET] = state.energy[r, ENERGY_BUDGET] + credit
    if not within_energy_budget(model, r, state.energy[r], credit, work, trial, ws):
        return -REJECT_ENERGY
    return 0


@kernel(inline="always")
def ring_rates(model, solver, r, state, v0, trial, h, ws, impulse_ratio, error):
    """Ring ``r``'s contact forces and its step-size limits (see :func:`try_step`): returns
    ``impulse_ratio`` and ``error`` with the ring's own taken in."""
    if model.contact_method != CONTACT_NONE:
        impulse = contact_impulse(model, solver, r, state, v0, trial, h, ws)
        if impulse > 0.0:
            impulse_ratio = min(impulse_ratio, model.impulse_bound[r] / impulse)
    if solver.rtol > 0.0:
        error = max(error, ring_error(model, solver, r, state, trial, h))
    return impulse_ratio, error


@kernel(inline="always")
def joint_energy(model, state, trial, ws, rc):
    """The rings' energies after a joint step and what the contact between them moved from ring to
    ring (:func:`step.joint_newton.contact_transfers`); a gain of the rings in contact taken back from
    their relative motion (:func:`step.joint_newton.pay_from_relative_motion`, constrained nodes put back
    at rest on their grounds; tallied as removed). False if the pairs do not fit."""
    for r in range(state.x.shape[0]):
        free_energy(model, r, trial.x[r], trial.v[r], ws, trial.energy[r])
    kicks = ws.collision.kinetic_change  # (always found: rings that collide through the barrier)
    gain = contact_transfers(model, state.x, trial.x, state.energy, trial.energy, kicks, rc)
    if gain > 0.0 and pay_from_relative_motion(model, trial.v, rc, gain):
        ws.energy_tally[TALLY_PROJECTED] += 1.0
        ws.energy_tally[TALLY_REMOVED] += gain
        for r in range(state.x.shape[0]):
            if rc.work[r] > 0.0:
                rest_on_grounds(ws.surface, trial.active[r], trial.x[r], trial.v[r], trial.a[r])
                free_energy(model, r, trial.x[r], trial.v[r], ws, trial.energy[r])
        gain = contact_transfers(model, state.x, trial.x, state.energy, trial.energy, kicks, rc)
    return not math.isnan(gain)


@kernel
def step_rings(model, solver, state, v0, trial, h, ws, rc):
    """The trial step of every ring: returns (Newton corrections, impulse ratio, local error) as
    :func:`try_step`, a rejection as ``(-code, 0, 0)``. Ring by ring (:func:`step_ring`,
    :func:`ring_rates`); with ``rc`` (rings that collide through the barrier), all rings jointly
    (:func:`joint_rings_step`) if a node starts within the contact distance of another ring
    (:func:`step.joint_newton.rings_touch`) or the step solved ring by ring met another ring on the way
    or at its end (:func:`step.joint_newton.rings_met`). A compiled call: numba prunes the joint step for
    ``rc`` None before it inlines or types any of it, so the env and every scene without it compile
    the ring-by-ring loop only."""
    if rc is not None:
        if rings_touch(model, state.x, rc):
            return joint_rings_step(model, solver, state, v0, trial, h, ws, rc)
    total = 0
    impulse_ratio = math.inf
    error = 0.0
    for r in range(state.x.shape[0]):
        its = step_ring(model, solver, r, state, v0, trial, h, ws)
        if its < 0:
            return its, 0.0, 0.0
        total += its
        impulse_ratio, error = ring_rates(model, solver, r, state, v0, trial, h, ws, impulse_ratio, error)
    if rc is not None:
        if rings_met(model, state.x, trial.x, rc):
            return joint_rings_step(model, solver, state, v0, trial, h, ws, rc)
    return total, impulse_ratio, error


@kernel
def joint_rings_step(model, solver, state, v0, trial, h, ws, rc):
    """The trial step of all rings solved jointly with the contact between rings
    (:func:`step.joint_newton.joint_newton`), then each ring's acceptance tests and step-size limits:
    returns (Newton corrections, impulse ratio, local error) as :func:`try_step`."""
    rc.mode[0] = COUPLED
    ws.energy_tally[TALLY_BOUNDARY_WORK] = 0.0  # (of a step tried ring by ring first)
    ws.energy_tally[TALLY_PROJECTED] = 0.0
    ws.energy_tally[TALLY_REMOVED] = 0.0
    copy_into(trial.active, state.active)
    its = joint_newton(model, solver, state, v0, trial, h, ws, rc)
    rc.mode[0] = PLAIN
    if its < 0:
        return -REJECT_NEWTON, 0.0, 0.0
    if not joint_energy(model, state, trial, ws, rc):
        return -REJECT_NEWTON, 0.0, 0.0
    impulse_ratio = math.inf
    error = 0.0
    for r in range(state.x.shape[0]):
        copy_into(ws.reaction, rc.reaction[r])
        copy_into(ws.friction, rc.friction[r])
        ws.arrival_work[0] = rc.arrival[r]
        code = ring_checks(model, r, state, trial, h, ws, rc.transfer[r])
        if code < 0:
            return code, 0.0, 0.0
        impulse_ratio, error = ring_rates(model, solver, r, state, v0, trial, h, ws, impulse_ratio, error)
    return its, impulse_ratio, error


@kernel(inline="always")
def contact_impulse(model, solver, r, state, v0, trial, h, ws):
    """Ring ``r``'s contact forces into ``trial.contact_force`` and its contact impulse (N s) for the
    step-size control (see :func:`try_step`)."""
    m = model.node_mass[r] * arrival_factor(solver)
    jx = 0.0
    jy = 0.0
    for i in range(state.x.shape[1]):
        g = trial.active[r, i]
        if g == FREE:
            trial.contact_force[r, i, 0] = 0.0
            trial.contact_force[r, i, 1] = 0.0
            continue
        nx, ny, _ = frame(model.grounds, g, trial.x[r, i, 0], trial.x[r, i, 1])
        fn, ft = ws.reaction[i], ws.friction[i]
        fx = fn * nx - ft * ny
        fy = fn * ny + ft * nx
        trial.contact_force[r, i, 0] = fx
        trial.contact_force[r, i, 1] = fy
        jx += h * fx
        jy += h * fy
        # the reaction that stops the node's start velocity into the surface (an arriving node, or
        # a resting one pushed by a collision impulse): kappa m (v_n - w_n + gap / h), relative to
        # the surface at the step's start
        start = ws.surface_start
        x, y = state.x[r, i, 0], state.x[r, i, 1]
        gap = max(0.0, nx * x + ny * y - start[g, 2])
        if model.grounds[g, GROUND_KIND] != GROUND_PLANE:
            _, _, gap = frame(start, g, x, y)
            gap = max(0.0, gap)
        wx, wy = surface_velocity(start, g, x, y)
        wn = wx * nx + wy * ny
        vn = min(0.0, v0[r, i, 0] * nx + v0[r, i, 1] * ny - wn + gap / h)
        if vn < 0.0:
            jx += m * vn * nx
            jy += m * vn * ny
            # and the friction that comes with it, at most mu times that normal impulse
            jt = h * ft
            kept = math.copysign(max(0.0, abs(jt) - model.grounds[g, GROUND_FRICTION] * m * -vn), jt)
            jx += (jt - kept) * ny  # the tangent is (-n_y, n_x)
            jy -= (jt - kept) * nx
    return math.sqrt(jx * jx + jy * jy)


@kernel(inline="always")
def ring_error(model, solver, r, state, trial, h):
    """Ring ``r``'s scaled local error (:func:`step.local_error.error_norm`; at most 1 is accepted)."""
    return error_norm(
        model, solver, r, h, state.x[r], trial.x[r], state.a[r], trial.a[r], state.active[r], trial.active[r]
    )


@kernel(inline="always")
def try_step(model, solver, state, trial, t, h, ws):
    """One step of every ring from ``state`` at time ``t`` (s) into ``trial`` at ``t + h``; the
    grounds at both times go to ``ws.surface_start`` and ``ws.surface``
    (:mod:`ballenv.physics.ground.motion`).

    Returns (Newton corrections, impulse ratio, local error): the impulse ratio is the smallest over
    rings of ``model.impulse_bound`` over the ring's contact impulse (N s; inf without contact), the
    local error the largest scaled estimate (:func:`ring_error`; 0 without error control). Returns
    (-code, 0, 0) if the step must be rejected, with ``code`` one of the ``REJECT_`` reasons: a
    ring's Newton iteration failed, a ring gained energy beyond what
    :func:`step.energy_budget.within_energy_budget` removes, a ring crossed itself
    (``model.reject_self_intersection``), or a node of one ring ended inside another
    (``model.collide``).

    A ring's contact impulse is
    ``|h sum_i f_i + kappa sum_i m min(0, v_n,i - w_n + gap_i / h) n|``: the ring's total ground
    reaction impulse over the step (its momentum change by contact, the paper's ``f dt``) less the
    reaction that stops the constrained nodes' start velocity into their ground (normal velocity
    ``v_n < 0`` relative to the surface's ``w_n`` and distance ``gap`` at the step's start: nodes
    arriving in this step, and resting nodes that a collision impulse pushed into the ground). Such
    a node loses its normal momentum in whatever step it happens (a point mass hitting a rigid
    wall), so no step size could bring that part under a tolerance; the remainder grows with ``h``
    and is what the step-size control bounds. The same holds for the Coulomb friction on such a node
    while it is stopped, at most ``mu`` times that normal impulse: its tangential impulse is counted
    only above ``mu kappa m |v_n - w_n + gap / h|`` (without this, a sliding impact left a floor
    ``mu m v_n`` per arriving node that no step size could bring under its bound). ``kappa`` is the
    integrator's reaction to an arrival per unit momentum: 1 for backward Euler,
    ``(1 - alpha_m) / beta`` for generalized-alpha (whose Newmark update reflects the node's normal
    velocity before :func:`ground.contact.rest_on_grounds` removes it).

    With ring collision through the barrier (``model.ring_barrier``, ``ws.ring_contact``), a step
    whose start has a node within the contact distance of another ring, or that, solved ring by
    ring, ends within it or passes a node through a wall on the way
    (:func:`step.joint_newton.rings_touch`, :func:`step.joint_newton.rings_met`), is solved for all rings at
    once (:func:`step_rings`); each ring's energy budget is credited with what the contact moved to it
    (:func:`step.joint_newton.contact_transfers`, summing to minus the change of the contact energy).
    Otherwise, with ring collision, the collision impulses are found on the predicted positions
    ``x0 + h v0`` and added to the start velocities (``walls/impulses.py``); each ring's energy guard
    and energy budget are credited with the change of its kinetic energy by them. Their sum over
    rings is negative (energy lost) except where they push out nodes that start the step inside the
    contact distance (a Baumgarte-type term): that net gain is tallied in ``ws.energy_tally``. They
    are not part of the contact impulse (the part that stops an approaching node does not shrink
    with the step).
    """
    ws.energy_tally[:] = 0.0
    ground_surfaces(model.grounds, t, ws.surface_start)
    ground_surfaces(model.grounds, t + h, ws.surface)
    v0 = ws.collision.kicked if collision_kicks(model, state, h, ws) else state.v
    total, impulse_ratio, error = step_rings(model, solver, state, v0, trial, h, ws, ws.ring_contact)
    if total < 0:
        return total, 0.0, 0.0
    if model.collide and rings_intrude(trial.x, model.thickness, ws.ring_pairs):
        return -REJECT_INTRUSION, 0.0, 0.0
    return total, impulse_ratio, error


@kernel
def doubled_step(model, solver, state, trial, t, h, its, impulse_ratio, error, ws, dw):
    """With error control in contact (``dw``, ``ws.doubling``: not None), the contact errors of a step
    of size ``h`` (s) from ``state`` at ``t`` (s) whose whole step ``trial`` (:func:`try_step`: ``its``
    Newton corrections, ``impulse_ratio``, local error ``error``) has a ring in contact
    (:mod:`ballenv.physics.step.contact_error`): the arrival error, then, if that is within tolerance, the
    step again as two halves, whose end ``trial`` becomes (with the energy tallies of both) and whose
    difference from the whole step is the doubling error. Returns (Newton corrections, impulse ratio, local
    error) as :func:`try_step`, the error the largest of ``error``, the halves' and the contact errors,
    each as a norm with the integrator's exponent (:func:`step.local_error.error_exponent`). Otherwise
    returns its arguments (numba prunes the rest for ``dw`` None: the step of a scene without error
    control holds none of this code)."""
    if dw is None:
        return its, impulse_ratio, error
    if its < 0 or not in_contact(state, trial):
        return its, impulse_ratio, error
    exponent = 1.0 / error_exponent(solver)  # a norm with factor norm^(-1) as one with the integrator's
    for r in range(state.x.shape[0]):
        error = max(error, arrival_norm(model, solver, r, state, trial, ws.surface_start) ** exponent)
    if error > 1.0:
        return its, impulse_ratio, error
    total = its
    start = state
    end = dw.mid
    for half in range(2):
        its_half, _, error_half = try_step(model, solver, start, end, t + 0.5 * half * h, 0.5 * h, ws)
        if its_half < 0:
            return its_half, 0.0, 0.0
        total += its_half
        error = max(error, error_half)
        if half == 0:
            copy_into(dw.tally, ws.energy_tally)
            start = dw.mid
            end = dw.fine
    for k in range(ws.energy_tally.shape[0]):
        ws.energy_tally[k] += dw.tally[k]
    ground_surfaces(model.grounds, t, ws.surface_start)
    exponent = 0.5 / error_exponent(solver)  # a norm with factor norm^(-1/2) as one with the integrator's
    for r in range(state.x.shape[0]):
        error = max(error, doubling_norm(model, solver, r, trial, dw.fine) ** exponent)
    copy_state(trial, dw.fine)
    return total, impulse_ratio, error


@kernel
def record(model, k, t, state, rec):
    """Write ``state`` at time ``t`` (s) as record ``k`` of ``rec``."""
    rec.t[k] = t
    copy_into(rec.x[k], state.x)
    copy_into(rec.v[k], state.v)
    copy_into(rec.contact_force[k], state.contact_force)
    for r in range(state.x.shape[0]):
        rec.pressure[k, r] = ring_pressure(model, r, state.x[r])


@kernel(inline="always")
def copy_state(state, trial):
    """``state`` <- ``trial``, field by field."""
    copy_into(state.x, trial.x)
    copy_into(state.v, trial.v)
    copy_into(state.a, trial.a)
    copy_into(state.active, trial.active)
    copy_into(state.contact_force, trial.contact_force)
    copy_into(state.energy, trial.energy)


@kernel(inline="always")
def step_end(solver, clock, counters, t_end, landing):
    """The end of the next step: ``(stop, at_end, at_grid)``: the time (s) the step from
    ``clock[CLOCK_T]`` with size ``clock[CLOCK_H]`` stops at, shortened to land on the fixed grid
    (not adaptive), the ``landing`` time (s; inf for none: the first of an actuation's window,
    :func:`step.actuation.drive_landing`, and a ring's first touch,
    :func:`ground.touchdown.touchdown_landing`) and ``t_end``, and which it landed on. Output times
    do not shorten steps (:mod:`ballenv.physics.step.dense_output`)."""
    t = clock[CLOCK_T]
    eps = time_tolerance(solver)
    stop = min(t + clock[CLOCK_H], landing)
    grid = (counters[COUNT_GRID] + 1) * solver.dt
    if not solver.adaptive:
        stop = min(stop, grid)
    stop = min(stop, t_end)
    at_end = stop >= t_end - eps
    at_grid = not solver.adaptive and abs(stop - grid) <= eps
    if at_grid:  # on the grid itself: a clock summing steps of a non-binary dt drifts off it
        stop = grid
    if at_end:
        stop = t_end
    return stop, at_end, at_grid


@kernel(inline="always")
def records_needed(t, stop, output_dt, eps):
    """Records a step from ``t`` to ``stop`` (s) may write: its end and, with ``output_dt`` > 0,
    the output times inside it (:func:`dense_output.outputs_within`)."""
    return 1 + (outputs_within(t, stop, output_dt, eps) if output_dt > 0.0 else 0)


@kernel(inline="always")
def on_output(t, output_dt, eps):
    """Whether ``t`` (s) is an output time ``k output_dt`` (within ``eps``)."""
    return abs(t - output_dt * round(t / output_dt)) <= eps


@kernel(inline="always")
def step_outcome(solver, clock, counters, h, its, ratio, by_error):
    """Bookkeeping of a trial step of size ``h`` (s) that returned ``its`` Newton corrections and
    ``ratio``, the step-size factor its tolerances allow (:func:`advance`; ``by_error``: the local
    error, not the contact impulse, set it):
    ``CONTINUE`` (retry with the new ``clock[CLOCK_H]``), ``STATUS_DONE`` (accept it) or a failure
    status. A rejected step (``its`` < 0) is retried with half the step; an adaptive step whose
    ``ratio`` is below 1 with ``h * max(0.2, 0.9 ratio)``."""
    if its < 0:
        counters[COUNT_REJECTION] = -its
        counters[COUNT_BY_REASON - its - 1] += 1
        counters[COUNT_REJECTED] += 1
        clock[CLOCK_H] = 0.5 * h
        return STATUS_STEP_TOO_SMALL if clock[CLOCK_H] < solver.dt_min else CONTINUE
    counters[COUNT_NEWTON] += its
    if solver.adaptive and ratio < 1.0:
        if h <= 1.001 * solver.dt_min:  # (h = stop - t carries round-off)
            return STATUS_IMPULSE_AT_DT_MIN
        counters[COUNT_REJECTED] += 1
        counters[COUNT_ERROR_REJECTED if by_error else COUNT_IMPULSE_REJECTED] += 1
        clock[CLOCK_H] = max(solver.dt_min, h * max(0.2, 0.9 * ratio))
        return CONTINUE
    return STATUS_DONE


@kernel(inline="always")
def accept(model, solver, ws, state, trial, clock, counters, h, stop, at_grid, ratio, rec):
    """Take the trial step ``state -> trial`` of size ``h`` (s) ending at ``stop`` (s): tallies,
    events, the state, the clock, and the next step size: adaptive, grown by ``min(growth, 1 +
    (ratio - 1) / 2)`` (cautious; ``ratio``: see :func:`advance`) up to
    ``dt``; fixed, back to ``dt`` once on the grid, and a step that rejections halved doubled back
    toward it after each accepted step (the next stop still lands on the grid: :func:`step_end`)."""
    counters[COUNT_STEPS] += 1
    counters[COUNT_ENERGY_PROJECTED] += int(ws.energy_tally[TALLY_PROJECTED])
    clock[CLOCK_ENERGY_REMOVED] += ws.energy_tally[TALLY_REMOVED]
    clock[CLOCK_COLLISION_GAIN] += ws.energy_tally[TALLY_COLLISION_GAIN]
    clock[CLOCK_BOUNDARY_WORK] += ws.energy_tally[TALLY_BOUNDARY_WORK]
    counters[COUNT_EVENTS] = detect_events(
        model, ws.surface_start, state, trial, clock[CLOCK_T], h, rec.events, counters[COUNT_EVENTS]
    )
    copy_state(state, trial)
    clock[CLOCK_T] = stop
    if solver.adaptive:
        growth = min(solver.growth, max(1.0, 1.0 + 0.5 * (ratio - 1.0)))
        clock[CLOCK_H] = min(max(h, clock[CLOCK_H]) * growth, solver.dt)
    elif at_grid:
        counters[COUNT_GRID] += 1
        clock[CLOCK_H] = solver.dt
    else:  # unchanged unless rejections halved it: then twice the step just taken
        clock[CLOCK_H] = min(max(2.0 * h, clock[CLOCK_H]), solver.dt)


@kernel
def advance(model, solver, ws, state, trial, clock, counters, t_pause, t_end, output_dt, rec, drive):
    """Step ``state`` from ``clock[CLOCK_T]`` to ``t_end``, pausing (returning) after the first step
    that reaches ``t_pause`` (<= ``t_end``; for progress reports).

    Records into ``rec`` from index ``counters[COUNT_RECORDS]`` on: every accepted step if
    ``output_dt == 0``, else at multiples of ``output_dt`` and ``t_end``, interpolated within the
    accepted steps (:mod:`ballenv.physics.step.dense_output`: the steps are those of a run without
    records); events go to ``rec.events`` rows (t, ring, kind, centre-of-mass height). Returns
    STATUS_DONE, STATUS_BUFFER_FULL (call again with room), STATUS_STEP_TOO_SMALL (rejected steps
    halved the step below ``dt_min``; ``counters[COUNT_REJECTION]`` says why the last one was) or
    STATUS_IMPULSE_AT_DT_MIN (the contact impulse exceeds ``impulse_tol`` even at ``dt_min``); on
    failure the state is the last accepted one.

    ``drive``: actuation spread over time (a ``model.Drive``: gas ramps, spread impulses; each
    step lands on their windows' ends and first takes its share, :mod:`ballenv.physics.step.actuation`), or
    None: numba then prunes those calls and compiles none of their code.

    Step control: a rejected step (see :func:`try_step`) is retried with half the step, adaptive or
    not. With ring collision, every step is first kept within :func:`walls.impulses.collision_step_limit` (no
    node can cross more than half the contact distance toward another ring in it). Adaptive: the step's
    ``ratio`` is the smallest of ``bound / (f h)`` over rings with ground contact (the contact
    impulse, :func:`try_step`, against ``model.impulse_bound``) and, with error control
    (``solver.rtol`` > 0), ``err^(-1/(p+1))`` of the scaled local error ``err``
    (:mod:`ballenv.physics.step.local_error`), and for a step in contact its contact errors
    (:func:`doubled_step`). A
    step with ``ratio`` < 1 is retried with ``h * max(0.2, 0.9 ratio)``;
    accepted steps grow by ``min(growth, 1 + (ratio - 1) / 2)`` (cautious), up to ``dt``. Under
    error control with the "impulse" contact control, a step of a ring in flight ends at its
    predicted first touch of a ground (:mod:`ballenv.physics.ground.touchdown`).
    """
    capacity = rec.t.shape[0]
    n_rings = state.x.shape[0]
    eps = time_tolerance(solver)
    while clock[CLOCK_T] < t_pause:
        if counters[COUNT_EVENTS] + 3 * n_rings > rec.events.shape[0]:
            return STATUS_BUFFER_FULL
        if model.collide:
            limit = collision_step_limit(state.x, state.v, model.thickness, clock[CLOCK_H], ws.ring_pairs)
            clock[CLOCK_H] = max(min(clock[CLOCK_H], limit), solver.dt_min)
        landing = touchdown_landing(model, solver, ws, state, clock[CLOCK_T], clock[CLOCK_H])
        if drive is not None:  # (pruned by numba for a drive of None: no code)
            landing = min(landing, drive_landing(solver, clock[CLOCK_T], drive))
        stop, at_end, at_grid = step_end(solver, clock, counters, t_end, landing)
        if counters[COUNT_RECORDS] + records_needed(clock[CLOCK_T], stop, output_dt, eps) > capacity:
            return STATUS_BUFFER_FULL
        if drive is not None:
            drive_step(model, solver, state, clock[CLOCK_T], stop, ws, drive)
        h = stop - clock[CLOCK_T]
        its, impulse_ratio, error = try_step(model, solver, state, trial, clock[CLOCK_T], h, ws)
        its, impulse_ratio, error = doubled_step(
            model, solver, state, trial, clock[CLOCK_T], h, its, impulse_ratio, error, ws, ws.doubling
        )
        error_factor = math.inf if error == 0.0 else error ** -error_exponent(solver)
        ratio = min(impulse_ratio, error_factor)
        status = step_outcome(solver, clock, counters, h, its, ratio, error_factor < impulse_ratio)
        if status == CONTINUE:
            continue
        if status != STATUS_DONE:
            return status
        if output_dt > 0.0:
            counters[COUNT_RECORDS] = record_within(
                model, state, trial, clock[CLOCK_T], h, output_dt, eps, rec, counters[COUNT_RECORDS]
            )
        accept(model, solver, ws, state, trial, clock, counters, h, stop, at_grid, ratio, rec)
        if drive is not None:
            drive_step(model, solver, state, stop, stop, ws, drive)  # a ramp ending here: its end amount
        if output_dt == 0.0 or at_end or on_output(stop, output_dt, eps):
            record(model, counters[COUNT_RECORDS], stop, state, rec)
            counters[COUNT_RECORDS] += 1
    return STATUS_DONE
