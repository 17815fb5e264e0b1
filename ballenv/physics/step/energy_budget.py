"""A ring's energy budget: what it may hold after a step, and the removal of a small excess.

Nothing in a scene adds energy but actuation (the gas amount, paddle impulses), the push-out of
collision impulses and moving grounds (:func:`boundary_work`): the gas and gravity are potentials;
damping, friction and fixed grounds' constraints only remove it. Each ring carries
``State.energy[r]`` (columns ``base.layout.ENERGY``): its energy (J), its free part (kinetic plus elastic
and gas energy above its inflated circle at rest, ``Model.rest_energy``; gravity left out) and its
budget (its energy at the start plus what actuation, collision impulses and moving grounds gave it
since). The energy parts come from the effects (:func:`effects.assembly.ring_energy`).
"""

import math

from ..base.geometry import centre_of_mass
from ..base.jit import kernel
from ..base.layout import (
    ENERGY_BUDGET,
    ENERGY_FREE,
    ENERGY_MOTION,
    ENERGY_TOTAL,
    GROUND_PLANE,
    SURFACE_KIND,
    SURFACE_OFFSET,
    SURFACE_RADIUS,
    SURFACE_TURN,
    SURFACE_VELOCITY,
    TALLY_BOUNDARY_WORK,
    TALLY_PROJECTED,
    TALLY_REMOVED,
)
from ..effects.assembly import ENERGY_KINETIC, gravity_column, ring_energy
from ..ground.contact import FREE, rest_on_grounds
from ..walls.self_barrier import barrier_energy, find_pairs, near_pairs, reach, stiffness
from ..walls.wall_limits import wall_limit_energy

ENERGY_GROWTH_TOL = 1e-2  # largest energy gain of a step, relative to the ring's free energy
WORK_ERROR_TOL = 0.1  # largest unpayable excess of a step on a moving ground, relative to its |work|


@kernel
def free_energy(model, r, x, v, ws, out):
    """``out[ENERGY_TOTAL]`` = the energy (J) of ring ``r``; ``out[ENERGY_FREE]`` = its free part:
    kinetic plus elastic, gas and self-contact barrier energy (:func:`walls.self_barrier.barrier_energy`)
    above the inflated circle at rest (``Model.rest_energy``), gravity left out;
    ``out[ENERGY_MOTION]`` = its kinetic energy. The effects' parts are left in ``ws.energy``; the
    budget column of ``out`` is left alone."""
    parts = ws.energy
    out[ENERGY_TOTAL] = ring_energy(model, r, x, v, parts)
    if model.self_barrier:
        out[ENERGY_TOTAL] += self_contact_energy(model, r, x, ws.barrier)
    g = gravity_column(model)
    out[ENERGY_FREE] = out[ENERGY_TOTAL] - (parts[g] if g >= 0 else 0.0) - model.rest_energy[r]
    out[ENERGY_MOTION] = parts[ENERGY_KINETIC]


@kernel(inline="always")
def _surface_displacement(start, end, g, h):
    """Ground ``g``'s surface displacement (m) over a step of ``h`` (s):
    ``(d(t1) - d(t0)) n + h (t . w) t``."""
    nx, ny = end[g, 0], end[g, 1]
    normal = end[g, SURFACE_OFFSET] - start[g, SURFACE_OFFSET]
    slide = h * (-ny * end[g, SURFACE_VELOCITY] + nx * end[g, SURFACE_VELOCITY + 1])
    return normal * nx - slide * ny, normal * ny + slide * nx


@kernel
def boundary_work(start, end, active, reaction, friction, h):
    """Work (J) the grounds' surfaces do on a ring in a step of ``h`` (s), credited to its budget:

        W = sum_i f_i . ds_g(i),      f_i = N_i n + F_i t,
        ds = (d(t1) - d(t0)) n + h (t . w) t,

    over the ring's constrained nodes ``i`` at the step's end (``active[i]`` = their ground ``g``),
    with the normal reaction ``N_i`` (``reaction``, N), the friction force ``F_i`` along
    ``t = (-n_y, n_x)`` (``friction``, N) and ``ds`` (m) the surface's displacement over the step,
    ``h`` times its mean velocity (``start``, ``end``: the grounds at the step's start and end, rows
    ``base.layout.SURFACE``; the tangential velocity ``t . w = t . u`` is constant). The power of the
    contact force on a node is ``f . v = f . w + f . (v - w)``: the first term is the ground's work,
    the second (the friction on the slip; the normal part vanishes, a constrained node moving with
    the surface along n) only dissipates. The force is the step's end force, as in backward
    Euler's energy balance (``sum_i f_i . (x1_i - x0_i)``; a node resting on the surface through
    the step moves along n by exactly ``n . ds``). 0 on fixed grounds. On a drum turning by
    ``theta(t1) - theta(t0)`` (rad) over the step, the surface under a node on the circle moves by
    ``t . ds = s R (theta(t1) - theta(t0))`` along the node's tangent (``s`` the drum's kind, -1
    inside, +1 outside; ``R`` its radius, m) and not at all along n, so
    ``W_i = F_i s R (theta(t1) - theta(t0))``. The stepper adds the work of
    the impulses that put arriving nodes at rest on the surface (``Workspace.arrival_work``,
    :func:`ground.contact.rest_on_grounds`): ``sum_i m (w_n - v_n,i) w_n`` over the velocities the step's
    kinematics gave them."""
    work = 0.0
    for i in range(active.shape[0]):
        g = active[i]
        if g == FREE:
            continue
        if end[g, SURFACE_KIND] != GROUND_PLANE:
            turn = end[g, SURFACE_TURN] - start[g, SURFACE_TURN]
            work += friction[i] * end[g, SURFACE_KIND] * end[g, SURFACE_RADIUS] * turn
            continue
        nx, ny = end[g, 0], end[g, 1]
        dx, dy = _surface_displacement(start, end, g, h)
        fx = reaction[i] * nx - friction[i] * ny
        fy = reaction[i] * ny + friction[i] * nx
        work += fx * dx + fy * dy
    return work


@kernel
def self_contact_energy(model, r, x, bw):
    """The self-contact barrier's energy (J) of ring ``r`` at nodes ``x``, with its wall limits'
    (:func:`walls.wall_limits.wall_limit_energy`, fold and collapse): 0 without a pair within ``dhat``
    and no node or edge near a limit (then exactly nothing is added), or without the barrier's
    workspace (``bw`` None)."""
    if bw is None:
        return 0.0
    limits = wall_limit_energy(x, model.rest_len[r], model.ea[r], model.start_energy[r])
    if near_pairs(x, model.rest_len[r], reach(model, r), bw) == 0:
        return limits  # (no sweep where the step's end was found clear)
    count = find_pairs(x, x, model.rest_len[r], reach(model, r), bw)
    if count < 0:
        return math.inf
    return limits + barrier_energy(x, bw.pairs, count, stiffness(model, r), reach(model, r))


@kernel(inline="always")
def exchanged_energy(row):
    """The energy (J) a ring with carried energy ``row`` (columns ``base.layout.ENERGY``) moves
    between its parts: its free energy, or its kinetic energy where that is more. The two agree
    wherever the inflated circle at rest is the ring's least energy (free >= kinetic); a ring whose
    circle is unstable (pressed by a regulated external pressure above its buckling load) turns
    the pressure's work into motion while its free energy stays near 0 or falls below it."""
    return max(row[ENERGY_FREE], row[ENERGY_MOTION])


@kernel
def energy_grew(total_before, free_before, total_after, free_after):
    """True if a step from energy ``total_before`` to ``total_after`` (J; ``free_``: the energy each
    moves between its parts, :func:`exchanged_energy`) raised the total by more than
    ``ENERGY_GROWTH_TOL`` times their mean, or gave a non-finite energy."""
    if not math.isfinite(total_after):
        return True
    free = max(0.5 * (free_before + free_after), 0.0)
    return total_after - total_before > ENERGY_GROWTH_TOL * free + 1e-12 * abs(total_before)


@kernel
def _energy_scale(model, r, x, parts):
    """Size (J) of the terms that make up ring ``r``'s energy, for round-off tolerances: the sum of
    |energy parts| ``parts``, with gravity's part taken node by node, ``m |g_d x_i,d|`` summed
    (the ring's gravity energy can cancel to nearly 0 while its nodes' terms do not)."""
    scale = 0.0
    g = gravity_column(model)
    for k in range(parts.shape[0]):
        if k != g:
            scale += abs(parts[k])
    if model.use_gravity:
        for i in range(x.shape[0]):
            for d in range(2):
                scale += model.node_mass[r] * abs(model.gravity[d] * x[i, d])
    return scale


@kernel
def within_energy_budget(model, r, before, kick, work, trial, ws):
    """Hold ring ``r``'s energy after a trial step to its budget ``trial.energy[r, ENERGY_BUDGET]``
    (J): its energy at the start of the run plus what actuation, collision impulses and moving
    grounds gave it since. Nothing else in a scene adds energy: the gas and gravity are potentials;
    damping, friction and fixed grounds' constraints only remove it. ``before`` is the ring's
    carried energy row before the step, ``kick`` the energy the step gave it from outside: the
    kinetic energy of its collision impulses plus the moving grounds' work ``work`` (J,
    :func:`boundary_work`).

    A gain of the step above ``ENERGY_GROWTH_TOL`` times the mean energy it exchanges
    (:func:`exchanged_energy`) is a spurious solution
    (far too large implicit steps of a nonlinear ring converge to some): returns False, the step is
    rejected and retried smaller. Smaller gains are the integrator's truncation error
    (generalized-alpha is not energy-stable for a nonlinear ring: the energy of a spinning ring
    oscillates by about ``h^2.5``); whatever of it lifts the energy above the budget is removed from
    the ring's velocities relative to its centre of mass, keeping its momentum
    (:func:`step.energy_budget.remove_internal_kinetic_energy`), ``trial.energy[r]`` is recomputed and the
    removal is tallied in ``ws.energy_tally``; ground-constrained nodes are then put back at rest
    on their ground in its normal direction (``ws.surface``; on a moving ground, the work of that
    velocity change is credited to the budget and tallied). If the ring's spin and deformation hold
    too little kinetic energy to pay the excess (a ring in rigid translation), an excess within
    round-off (1e-12 of :func:`_energy_scale`) is accepted as it is (on a moving ground, with the
    budget raised to the energy: an excess carried on could not be paid by the ever smaller work
    of ever smaller retried steps); so is, on a moving ground, an excess within ``WORK_ERROR_TOL``
    of the step's ``|work|`` (the integrator's error of that work,
    e.g. a node leaving the surface within the step: a ball riding a plate has no internal motion
    to pay it), with the budget raised to the
    energy and the excess tallied as boundary work; a larger one returns False. ``ws.energy`` must
    hold the energy parts of the trial state (as :func:`free_energy` leaves them)."""
    after = trial.energy[r]
    if energy_grew(
        before[ENERGY_TOTAL] + kick,
        exchanged_energy(before) + kick,
        after[ENERGY_TOTAL],
        exchanged_energy(after),
    ):
        return False
    excess = after[ENERGY_TOTAL] - after[ENERGY_BUDGET]
    if excess <= 0.0:
        return True
    if not remove_internal_kinetic_energy(trial.x[r], trial.v[r], model.node_mass[r], excess):
        round_off = excess <= 1e-12 * _energy_scale(model, r, trial.x[r], ws.energy)
        if round_off and not model.moving_grounds:
            return True
        if not round_off and excess > WORK_ERROR_TOL * abs(work):
            return False
        after[ENERGY_BUDGET] = after[ENERGY_TOTAL]
        ws.energy_tally[TALLY_BOUNDARY_WORK] += excess
        return True
    reset = rest_on_grounds(ws.surface, trial.active[r], trial.x[r], trial.v[r], trial.a[r])
    free_energy(model, r, trial.x[r], trial.v[r], ws, after)
    if model.moving_grounds:  # the surface's work putting the nodes back on it
        after[ENERGY_BUDGET] += model.node_mass[r] * reset
        ws.energy_tally[TALLY_BOUNDARY_WORK] += model.node_mass[r] * reset
    ws.energy_tally[TALLY_PROJECTED] += 1.0
    ws.energy_tally[TALLY_REMOVED] += excess
    return True


@kernel
def remove_internal_kinetic_energy(x, v, m, excess):
    """Lower the kinetic energy of a ring (nodes ``x`` (N, 2) m, velocities ``v`` (N, 2) m/s, equal
    node masses ``m`` kg) by ``excess`` (J) without changing its momentum: the velocities relative
    to the mean ``V`` are scaled, ``v_i <- V + s (v_i - V)`` with ``s = sqrt(1 - excess / K_int)`` and
    ``K_int = m/2 sum |v_i - V|^2`` the kinetic energy of spin and deformation. This is the
    smallest change of ``v`` (in the mass norm) that removes ``excess`` and keeps the momentum; it
    lowers the angular momentum about the centre of mass by the factor ``s`` (a velocity
    post-process like Su, Sheth & Fedkiw's energy clamp, IEEE TVCG 2013). Returns False, leaving
    ``v`` untouched, if ``K_int <= excess``.
    """
    n = v.shape[0]
    _, _, vx, vy = centre_of_mass(x, v)
    internal = 0.0
    for i in range(n):
        internal += (v[i, 0] - vx) ** 2 + (v[i, 1] - vy) ** 2
    internal *= 0.5 * m
    if not internal > excess:
        return False
    keep = math.sqrt(1.0 - excess / internal)
    for i in range(n):
        v[i, 0] = vx + keep * (v[i, 0] - vx)
        v[i, 1] = vy + keep * (v[i, 1] - vy)
    return True
