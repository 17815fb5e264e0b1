"""Compile a :class:`Scene` into the flat arrays the stepper works on (data flows one way).

``Model`` holds the physics (per-ring arrays of length R and scene scalars), ``State`` what the
stepper carries from step to step, ``Workspace`` the scratch arrays of one ring's Newton solve
(``integrator.Solver`` holds the numerical method). All are NamedTuples of NumPy
arrays and scalars: numba compiles them as records, they pickle, and they hold nothing else.
"""

import math
from typing import NamedTuple

import numpy as np
from numba import types
from numba.extending import overload

from . import ring as ring_geometry
from .assembly import (
    effect_modules,
    energy_parts,
    field_name,
    parameter_table,
    ring_energy,
)
from .barrier import PAIRS_PER_NODE
from .collision import CONTACT_COLUMNS, CONTACTS_PER_NODE
from .contact_error import LIFTOFF_IMPULSE, SCALE_GRAVITY
from .effects import EFFECTS
from .effects.damping import DAMPING_CENTRE_OF_MASS, DAMPING_NONE, DAMPING_RIGID
from .ground_motion import ground_array, grounds_move, surface_array
from .layout import (
    ENERGY,
    EVENT,
    PUSH,
    PUSH_T_END,
    RAMP,
    RAMP_T_END,
    TALLY,
)
from .linalg import BAND_COLUMNS, MAX_LOW_RANK, SOLVE_COLUMNS, zigzag_positions
from .ring_contact import ENTRIES_PER_PAIR, PAIR_COLUMNS
from .ring_contact import PAIRS_PER_NODE as RING_PAIRS_PER_NODE

CONTACT_NONE = 0
CONTACT_MASS_MODIFICATION = 1
CONTACT_PREDICTOR_CORRECTOR = 2


class Model(NamedTuple):
    node_mass: np.ndarray  # (R,) kg
    ea: np.ndarray  # (R,) N
    ei: np.ndarray  # (R,) N m^2
    rest_len: np.ndarray  # (R,) m
    rest_turn: np.ndarray  # (R,) rad
    width: np.ndarray  # (R,) m
    radius: np.ndarray  # (R,) m
    pressurised: np.ndarray  # (R,) bool
    gas_constant: np.ndarray  # (R,) Pa m^(2k)
    gas_exponent: float
    atmospheric_pressure: float  # Pa
    gravity: np.ndarray  # (2,) m/s^2
    use_gravity: bool
    damping: float  # 1/s
    damping_mode: int
    grounds: np.ndarray  # (G, GROUND.size): half-planes then drums (layout.GROUND, ground_motion.py)
    moving_grounds: bool  # a ground moves (ground_motion.py): its work is credited to the energy budget
    contact_method: int
    friction_regularization: float  # m/s
    impulse_bound: np.ndarray  # (R,) N s: the adaptive step's largest contact impulse per step
    rest_energy: np.ndarray  # (R,) J: stretching + gas energy of the inflated circle at rest
    thickness: np.ndarray  # (R,) m: wall thickness (the contact distance of two rings is h_a + h_b)
    start_energy: np.ndarray  # (R,) J: kinetic energy at the start, which the barriers are sized to stop
    collide: bool  # ring-ring collision (two or more rings and Scene.ring_collision)
    reject_self_intersection: bool  # reject trial states in which a ring crosses itself
    self_barrier: bool  # the self-contact barrier of far wall parts (barrier.py)
    ring_barrier: bool  # rings collide through the barrier, solved jointly (ring_contact.py), not impulses
    effect_parameters: np.ndarray  # (R,) records: one field per effect summed, its own parameters


class Drive(NamedTuple):
    """Actuation spread over time (``drive.py``), per ring: a gas ramp and a spread impulse.

    ``stepper.advance`` takes it as its own argument: None unless something asks for it
    (``Simulation`` on the first ramp or spread impulse, the env always), and then the step
    compiles none of its code, as with the self-contact barrier."""

    ramp: np.ndarray  # (R, RAMP.size): the gas ramp (layout.RAMP)
    push: np.ndarray  # (R, PUSH.size): the spread impulse (layout.PUSH)
    pushed: np.ndarray  # (R, N) bool: the nodes sharing the spread impulse


# Model fields with one entry per ring (the rest are scene-wide): a view of rings [a, b) slices these
PER_RING_FIELDS = (
    "node_mass", "ea", "ei", "rest_len", "rest_turn", "width", "radius", "pressurised", "gas_constant",
    "rest_energy", "thickness", "start_energy", "effect_parameters", "impulse_bound",
)  # fmt: skip


class CollisionWorkspace(NamedTuple):
    """Scratch of the ring-ring collision code (``collision.py``) for R rings of N nodes."""

    kicked: np.ndarray  # (R, N, 2) m/s: start velocities of the step after the collision impulses
    kinetic_change: np.ndarray  # (R,) J: change of each ring's kinetic energy by those impulses
    predicted: np.ndarray  # (R, N, 2) m: x0 + h v0, where the step's contacts are found
    edge_length: np.ndarray  # (N,) m: a ring's edge lengths at the predicted positions
    box: np.ndarray  # (R, 4) m: xmin, ymin, xmax, ymax
    margin: np.ndarray  # (R,) m: growth of each box in the broad phase
    order: np.ndarray  # (R,) int64: rings by the left edge of their grown box
    pairs: np.ndarray  # (R (R - 1) / 2, 2) int64: ring pairs of the broad phase
    contacts: np.ndarray  # (C, CONTACT_COLUMNS)
    orientation: np.ndarray  # (R,): +1 counter-clockwise ring, -1 clockwise
    velocity: np.ndarray  # (R, 3): centre-of-mass velocity (m/s), largest node speed relative to it


class BarrierWorkspace(NamedTuple):
    """Scratch of a ring's self-contact barrier (``barrier.py``) for rings of N nodes."""

    pairs: np.ndarray  # (PAIRS_PER_NODE N, 2) int64: candidate (node, edge) pairs
    n_pairs: np.ndarray  # (1,) int64: how many of them the Newton iteration uses
    mode: np.ndarray  # (1,) int64: newton.PLAIN (no barrier) or newton.SAFE
    active0: np.ndarray  # (N,) int64: the contact set at the step's start
    order: np.ndarray  # (N,) int64: edges by the left edge of their box
    left: np.ndarray  # (N,) m: left edge of each edge's box
    box: np.ndarray  # (N, 4) m: each node's box over a motion
    xn: np.ndarray  # (N, 2) m: the positions a Newton correction moves to
    slot: np.ndarray  # (N,) int64: first low-rank column of a node's off-band row, or -1
    nodes: np.ndarray  # (3,) int64: a pair's node and edge ends
    g: np.ndarray  # (6,): gradient of a pair's squared distance
    hess: np.ndarray  # (6, 6): its Hessian
    scratch: np.ndarray  # (6, 6)
    u: np.ndarray  # (2N, K) K = MAX_LOW_RANK + 2N: the effects' and the barrier's low-rank columns
    w: np.ndarray  # (2N, K)
    z: np.ndarray  # (2N, K + 1): B^-1 [u, rhs]
    cap: np.ndarray  # (K, K)
    coef: np.ndarray  # (K,)
    clear_x: np.ndarray  # (N, 2) m: the last positions found with no pair within dhat
    clear_key: np.ndarray  # (2,): their rest length and dhat (m); NaN: none found yet


class RingContactWorkspace(NamedTuple):
    """Scratch of the joint Newton step of rings in contact (``ring_contact.py``, ``ring_newton.py``)
    for R rings of N nodes; ``C`` coupling columns at most, ``P`` candidate pairs."""

    mode: np.ndarray  # (1,) int64: ring_newton.PLAIN (rings one by one) or COUPLED (jointly)
    pairs: np.ndarray  # (P, PAIR_COLUMNS) int64: ring a, node i, ring b, edge j
    n_pairs: np.ndarray  # (1,) int64
    box: np.ndarray  # (R, 4) m: each ring's box over a motion
    margin: np.ndarray  # (R,) m: its growth in the broad phase (the wall thickness)
    order: np.ndarray  # (R,) int64: rings by the left edge of their grown box
    ring_pairs: np.ndarray  # (R (R - 1) / 2, 2) int64: ring pairs of the broad phase
    near: np.ndarray  # (N,) int64: edges of one ring near another ring's box
    span: np.ndarray  # (2, 4) m: an edge's and a node's box over a motion
    g: np.ndarray  # (6,): gradient of a pair's squared distance
    hess: np.ndarray  # (6, 6): its Hessian
    scratch: np.ndarray  # (6, 6)
    hessians: np.ndarray  # (P, 6, 6): c_x hess E of each pair
    within: np.ndarray  # (P,) bool: the pair is within dhat (its Hessian counts)
    slot: np.ndarray  # (R, N) int64: first coupling column of a coupled node, or -1
    first: np.ndarray  # (R + 1,) int64: each ring's first coupling column
    column: np.ndarray  # (ENTRIES_PER_PAIR P,) int64: an off-ring entry's coupling column
    ring: np.ndarray  # (ENTRIES_PER_PAIR P,) int64: the ring of its unknown
    dof: np.ndarray  # (ENTRIES_PER_PAIR P,) int64: the unknown (2 node + component)
    value: np.ndarray  # (ENTRIES_PER_PAIR P,): its value
    dx: np.ndarray  # (R, N, 2) m: each ring's step displacement, the Newton unknown
    delta: np.ndarray  # (R, N, 2) m: the last correction (for backtracking)
    xe: np.ndarray  # (R, N, 2) m: the force evaluation point
    xn: np.ndarray  # (R, N, 2) m: the positions a correction moves to
    force: np.ndarray  # (R, N, 2) N: the contact force between rings at xe
    res: np.ndarray  # (R, 2N): each ring's residual
    step: np.ndarray  # (R, 2N): the joint Newton correction
    reaction: np.ndarray  # (R, N) N: ground reactions of the last residual
    friction: np.ndarray  # (R, N) N
    tangential: np.ndarray  # (R, N) N
    arrival: np.ndarray  # (R,) J: work of the velocity reset on moving grounds
    transfer: np.ndarray  # (R,) J: energy the contact between rings gave each ring in the step
    work: np.ndarray  # (R,) J: |work| of the contact force on each ring in the step
    cols: np.ndarray  # (2N, 1 + 2N): a ring's right-hand side and its coupling's unit columns
    z: np.ndarray  # (R, 2N, 1 + 2N): A_r^-1 of them, per ring
    zu: np.ndarray  # (2N, MAX_LOW_RANK + 2N): B^-1 U of a ring's low-rank columns
    ring_cap: np.ndarray  # (MAX_LOW_RANK + 2N, MAX_LOW_RANK + 2N): a ring's capacitance
    ring_piv: np.ndarray  # (MAX_LOW_RANK + 2N,) int64
    ring_coef: np.ndarray  # (MAX_LOW_RANK + 2N,)
    cap: np.ndarray  # (C, C): the coupling's capacitance I + W^T Z
    piv: np.ndarray  # (C,) int64
    coef: np.ndarray  # (C,)


class Workspace(NamedTuple):
    pos: np.ndarray  # (N,) zig-zag position of each node
    band: np.ndarray  # (2N, BAND_COLUMNS)
    u: np.ndarray  # (2N, MAX_LOW_RANK)
    w: np.ndarray  # (2N, MAX_LOW_RANK)
    cap: np.ndarray  # (MAX_LOW_RANK, MAX_LOW_RANK)
    coef: np.ndarray  # (MAX_LOW_RANK,)
    res: np.ndarray  # (2N,)
    work: np.ndarray  # (2N, SOLVE_COLUMNS)
    force: np.ndarray  # (N, 2)
    dx: np.ndarray  # (N, 2) displacement of the step, the Newton unknown
    delta: np.ndarray  # (N, 2) the last Newton correction (for backtracking)
    xe: np.ndarray  # (N, 2)
    ve: np.ndarray  # (N, 2)
    reaction: np.ndarray  # (N,) normal ground reaction of the last solve (N)
    friction: np.ndarray  # (N,) friction force along the ground's tangent (N)
    tangential: np.ndarray  # (N,) unconstrained residual along the ground's tangent, t . r_i (N)
    energy: np.ndarray  # (P,) energy parts (J), columns assembly.energy_parts of the model's effects
    energy_tally: np.ndarray  # (TALLY.size,) what the last trial step's energy budget saw (layout.TALLY)
    surface_start: np.ndarray  # (G, SURFACE.size) the grounds at the trial step's start (layout.SURFACE)
    surface: np.ndarray  # (G, SURFACE.size) the grounds at the trial step's end, where contact acts
    arrival_work: np.ndarray  # (1,) J: work of the last solve's velocity reset on moving grounds
    collision: CollisionWorkspace
    barrier: BarrierWorkspace | None  # None: the model has no self-contact barrier
    ring_pairs: CollisionWorkspace | None  # ``collision`` again where rings collide, else None
    ring_contact: RingContactWorkspace | None  # None: rings do not collide through the barrier
    doubling: "DoublingWorkspace | None"  # None: no step doubling in contact (``contact_error.py``)


class State(NamedTuple):
    x: np.ndarray  # (R, N, 2) m
    v: np.ndarray  # (R, N, 2) m/s
    a: np.ndarray  # (R, N, 2) m/s^2 (the generalized-alpha acceleration)
    active: np.ndarray  # (R, N) int64: constraining ground of each node, or -1
    contact_force: np.ndarray  # (R, N, 2) N
    energy: np.ndarray  # (R, ENERGY.size) J: each ring's energy, its free part and its budget (layout.ENERGY)


class DoublingWorkspace(NamedTuple):
    """The two half steps of a step in contact, whose difference from the whole step is its contact
    error (``contact_error.py``)."""

    mid: State  # the state after the first half step
    fine: State  # the state after the second half step
    tally: np.ndarray  # (TALLY.size,) the first half step's energy tallies (layout.TALLY)


class Recording(NamedTuple):
    t: np.ndarray  # (T,)
    x: np.ndarray  # (T, R, N, 2)
    v: np.ndarray  # (T, R, N, 2)
    pressure: np.ndarray  # (T, R)
    contact_force: np.ndarray  # (T, R, N, 2)
    events: np.ndarray  # (E, EVENT.size): t, ring, kind, centre-of-mass height (layout.EVENT)


def build_model(scene, effects=EFFECTS):
    """Per-ring arrays and scene scalars of ``scene`` for the forces of ``effects`` (the registry by
    default; :func:`assembly.check_effects` checks that their low-rank Jacobian columns fit
    ``linalg.MAX_LOW_RANK``), with their own parameters (``effect_parameters``, whose record dtype
    names the effects: see :mod:`.assembly`)."""
    rings = scene.rings
    n = rings[0].n_nodes
    p_atm = scene.atmospheric_pressure
    k = scene.gas_exponent
    area0 = np.array([ring_geometry.rest_area(ring_geometry.inflated_radius(r), n) for r in rings])
    pressurised = np.array([r.pressure is not None for r in rings])
    gauge = np.array([0.0 if r.pressure is None else r.pressure for r in rings])
    if scene.damping == 0.0:
        mode = DAMPING_NONE
    elif scene.damping_mode == "rigid":
        mode = DAMPING_RIGID
    else:
        mode = DAMPING_CENTRE_OF_MASS
    gravity = np.array(scene.gravity_vector, dtype=float)
    model = Model(
        node_mass=np.array([ring_geometry.node_mass(r) for r in rings]),
        ea=np.array([ring_geometry.stretching_stiffness(r) for r in rings]),
        ei=np.array([ring_geometry.bending_stiffness(r) for r in rings]),
        rest_len=np.array([ring_geometry.rest_edge_length(r.radius, n) for r in rings]),
        rest_turn=np.full(len(rings), ring_geometry.rest_turning_angle(n)),
        width=np.array([r.width for r in rings]),
        radius=np.array([r.radius for r in rings]),
        pressurised=pressurised,
        gas_constant=(gauge + p_atm) * area0**k,
        gas_exponent=float(k),
        atmospheric_pressure=float(p_atm),
        gravity=gravity,
        use_gravity=bool(np.any(gravity != 0.0)),
        damping=float(scene.damping),
        damping_mode=mode,
        grounds=ground_array(scene.grounds, scene.drums),
        moving_grounds=grounds_move(scene),
        contact_method=(
            CONTACT_NONE
            if not (scene.grounds or scene.drums)
            else CONTACT_MASS_MODIFICATION
            if scene.contact == "mass_modification"
            else CONTACT_PREDICTOR_CORRECTOR
        ),
        friction_regularization=float(scene.friction_regularization),
        impulse_bound=impulse_bounds(scene),
        rest_energy=np.zeros(len(rings)),
        thickness=np.array([r.thickness for r in rings]),
        start_energy=np.array([start_kinetic_energy(r) for r in rings]),
        collide=len(rings) > 1 and scene.ring_collision,
        reject_self_intersection=scene.self_intersection in ("reject", "barrier"),
        self_barrier=scene.self_intersection == "barrier",
        ring_barrier=len(rings) > 1 and scene.ring_collision and scene.self_intersection == "barrier",
        effect_parameters=effect_parameters(scene, effects),
    )
    _fill_rest_energy(model, rings)
    return model


def start_kinetic_energy(ring):
    """Kinetic energy (J) of ``ring``'s start (its inflated circle in rigid motion:
    ``Ring.velocity``, ``angular_velocity``): ``m/2 sum_i |v_i|^2``. The self-contact barrier, the
    wall limits and the contact between rings are made stiff enough to stop it
    (:func:`barrier.stiffness`, :mod:`.wall_limits`, :func:`ring_contact.pair_stiffness`)."""
    _, v = ring_geometry.initial_nodes(ring)
    return 0.5 * ring_geometry.node_mass(ring) * float(np.sum(v * v))


def _fill_rest_energy(model, rings):
    """``model.rest_energy[r]``: energy (J) of ring ``r`` on its inflated circle at rest, gravity
    left out: the floor of its potential energy (a regular polygon has no bending energy)."""
    names = energy_parts(effect_modules(model.effect_parameters))
    parts = np.zeros(len(names))
    for r, ring in enumerate(rings):
        x, _ = ring_geometry.initial_nodes(ring)
        total = ring_energy(model, r, x, np.zeros_like(x), parts)
        model.rest_energy[r] = total - (parts[names.index("gravity")] if "gravity" in names else 0.0)


def impulse_bounds(scene):
    """(R,) the adaptive step's bound on a ring's contact impulse per step (N s): ``Scene.impulse_tol``,
    or with error control (``Scene.step_rtol`` > 0) ``rtol M sqrt(g R)``, relative to the momentum of the
    ring (mass ``M``, kg; radius ``R``, m) falling its own radius (``g`` = 9.81 m/s^2 without
    gravity); with ``Scene.contact_error = "doubling"`` ``LIFTOFF_IMPULSE sqrt(rtol) M sqrt(g R)``:
    there the contact errors of :mod:`.contact_error` control the step in contact, and this bound
    only what they cannot see (a node released a step early)."""
    rtol = scene.step_rtol
    if rtol == 0.0:
        return np.full(len(scene.rings), float(scene.impulse_tol or 0.0))  # unused by fixed steps without it
    g = float(np.hypot(*scene.gravity_vector)) or SCALE_GRAVITY
    factor = rtol
    if scene.contact_error == "doubling":
        factor = LIFTOFF_IMPULSE * math.sqrt(rtol)
    return np.array([factor * ring_geometry.total_mass(r) * math.sqrt(g * r.radius) for r in scene.rings])


def effect_parameters(scene, effects=EFFECTS):
    """(R,) records of the effects' own per-ring parameters (see ``effects``' contract)."""
    table = parameter_table(effects, len(scene.rings))
    for k, effect in enumerate(effects):
        if effect.PARAMETERS:
            for r in range(len(scene.rings)):
                table[field_name(k, effect)][r] = effect.parameters(scene, r)
    return table


def build_drive(n_rings, n_nodes):
    """A :class:`Drive` for ``n_rings`` rings of ``n_nodes`` nodes, all off; each ring's gas must be
    held (``actuation.hold_gas``) before a ramp starts from it."""
    ramp = np.zeros((n_rings, RAMP.size))
    ramp[:, RAMP_T_END] = -np.inf
    push = np.zeros((n_rings, PUSH.size))
    push[:, PUSH_T_END] = -np.inf
    return Drive(ramp=ramp, push=push, pushed=np.zeros((n_rings, n_nodes), dtype=np.bool_))


def build_workspace(
    n_nodes, n_rings=1, effects=EFFECTS, barrier=True, ring_pairs=True, n_grounds=1, ring_contact=False,
    contact_pairs_per_node=RING_PAIRS_PER_NODE, doubling=False,
):  # fmt: skip
    """Scratch arrays for one ring's Newton solve and the scene's collision detection, allocated
    once per simulation (``effects``: the model's, for the size of the energy table). ``barrier``:
    the self-contact barrier's scratch, or None in its place for a model without it; ``ring_pairs``:
    the collision scratch once more as ``Workspace.ring_pairs`` (the ring-ring code's), or None
    for a model whose rings cannot collide; ``ring_contact``: the joint step's scratch of rings in
    contact through the barrier (needs ``barrier``; ``contact_pairs_per_node``: its room for
    candidate pairs, :func:`ring_contact.pairs_per_node`), else None. A step compiled with None in any of
    these places holds none of that code (numba prunes ``if ... is None`` on an argument before
    typing). ``n_grounds``: at least the model's number of grounds, for the rows of the grounds at
    the step's times. ``doubling``: the half steps' states of the step doubling in contact, else None
    (:func:`build_doubling_workspace`)."""
    n2 = 2 * n_nodes
    collision = build_collision_workspace(n_rings, n_nodes)
    return Workspace(
        pos=zigzag_positions(n_nodes),
        band=np.zeros((n2, BAND_COLUMNS)),
        u=np.zeros((n2, MAX_LOW_RANK)),
        w=np.zeros((n2, MAX_LOW_RANK)),
        cap=np.zeros((MAX_LOW_RANK, MAX_LOW_RANK)),
        coef=np.zeros(MAX_LOW_RANK),
        res=np.zeros(n2),
        work=np.zeros((n2, SOLVE_COLUMNS)),
        force=np.zeros((n_nodes, 2)),
        dx=np.zeros((n_nodes, 2)),
        delta=np.zeros((n_nodes, 2)),
        xe=np.zeros((n_nodes, 2)),
        ve=np.zeros((n_nodes, 2)),
        reaction=np.zeros(n_nodes),
        friction=np.zeros(n_nodes),
        tangential=np.zeros(n_nodes),
        energy=np.zeros(len(energy_parts(effects))),
        energy_tally=np.zeros(TALLY.size),
        surface_start=surface_array(n_grounds),
        surface=surface_array(n_grounds),
        arrival_work=np.zeros(1),
        collision=collision,
        barrier=build_barrier_workspace(n_nodes) if barrier else None,
        ring_pairs=collision if ring_pairs else None,
        ring_contact=(
            build_ring_contact_workspace(n_rings, n_nodes, contact_pairs_per_node)
            if ring_contact and barrier
            else None
        ),
        doubling=build_doubling_workspace(n_rings, n_nodes) if doubling else None,
    )


def build_doubling_workspace(n_rings, n_nodes):
    """A :class:`DoublingWorkspace` for ``n_rings`` rings of ``n_nodes`` nodes."""
    return DoublingWorkspace(
        mid=empty_state(n_rings, n_nodes), fine=empty_state(n_rings, n_nodes), tally=np.zeros(TALLY.size)
    )


MAX_COUPLING_COLUMNS = 1024  # largest joint capacitance (two columns per node coupled across rings)


def build_ring_contact_workspace(n_rings, n_nodes, pairs_per_node=RING_PAIRS_PER_NODE):
    """Scratch of the joint step of ``n_rings`` rings of ``n_nodes`` nodes in contact, with room
    for ``pairs_per_node`` candidate pairs per node."""
    n2 = 2 * n_nodes
    pairs = pairs_per_node * n_rings * n_nodes
    entries = ENTRIES_PER_PAIR * pairs
    k = MAX_LOW_RANK + n2
    c = min(n_rings * n2, MAX_COUPLING_COLUMNS)
    shape = (n_rings, n_nodes, 2)
    return RingContactWorkspace(
        mode=np.zeros(1, dtype=np.int64),
        pairs=np.zeros((pairs, PAIR_COLUMNS), dtype=np.int64),
        n_pairs=np.zeros(1, dtype=np.int64),
        box=np.zeros((n_rings, 4)),
        margin=np.zeros(n_rings),
        order=np.arange(n_rings, dtype=np.int64),
        ring_pairs=np.zeros((max(1, n_rings * (n_rings - 1) // 2), 2), dtype=np.int64),
        near=np.zeros(n_nodes, dtype=np.int64),
        span=np.zeros((2, 4)),
        g=np.zeros(6),
        hess=np.zeros((6, 6)),
        scratch=np.zeros((6, 6)),
        hessians=np.zeros((pairs, 6, 6)),
        within=np.zeros(pairs, dtype=np.bool_),
        slot=np.full((n_rings, n_nodes), -1, dtype=np.int64),
        first=np.zeros(n_rings + 1, dtype=np.int64),
        column=np.zeros(entries, dtype=np.int64),
        ring=np.zeros(entries, dtype=np.int64),
        dof=np.zeros(entries, dtype=np.int64),
        value=np.zeros(entries),
        dx=np.zeros(shape),
        delta=np.zeros(shape),
        xe=np.zeros(shape),
        xn=np.zeros(shape),
        force=np.zeros(shape),
        res=np.zeros((n_rings, n2)),
        step=np.zeros((n_rings, n2)),
        reaction=np.zeros((n_rings, n_nodes)),
        friction=np.zeros((n_rings, n_nodes)),
        tangential=np.zeros((n_rings, n_nodes)),
        arrival=np.zeros(n_rings),
        transfer=np.zeros(n_rings),
        work=np.zeros(n_rings),
        cols=np.zeros((n2, 1 + n2)),
        z=np.zeros((n_rings, n2, 1 + n2)),
        zu=np.zeros((n2, k)),
        ring_cap=np.zeros((k, k)),
        ring_piv=np.zeros(k, dtype=np.int64),
        ring_coef=np.zeros(k),
        cap=np.zeros((c, c)),
        piv=np.zeros(c, dtype=np.int64),
        coef=np.zeros(c),
    )


def build_barrier_workspace(n_nodes):
    """Scratch of the self-contact barrier for rings of ``n_nodes`` nodes."""
    n2 = 2 * n_nodes
    k = MAX_LOW_RANK + n2
    return BarrierWorkspace(
        pairs=np.zeros((PAIRS_PER_NODE * n_nodes, 2), dtype=np.int64),
        n_pairs=np.zeros(1, dtype=np.int64),
        mode=np.zeros(1, dtype=np.int64),
        active0=np.zeros(n_nodes, dtype=np.int64),
        order=np.arange(n_nodes, dtype=np.int64),
        left=np.zeros(n_nodes),
        box=np.zeros((n_nodes, 4)),
        xn=np.zeros((n_nodes, 2)),
        slot=np.full(n_nodes, -1, dtype=np.int64),
        nodes=np.zeros(3, dtype=np.int64),
        g=np.zeros(6),
        hess=np.zeros((6, 6)),
        scratch=np.zeros((6, 6)),
        u=np.zeros((n2, k)),
        w=np.zeros((n2, k)),
        z=np.zeros((n2, k + 1)),
        cap=np.zeros((k, k)),
        coef=np.zeros(k),
        clear_x=np.zeros((n_nodes, 2)),
        clear_key=np.full(2, np.nan),
    )


def build_collision_workspace(n_rings, n_nodes):
    """Scratch of the collision code for ``n_rings`` rings of ``n_nodes`` nodes."""
    return CollisionWorkspace(
        kicked=np.zeros((n_rings, n_nodes, 2)),
        kinetic_change=np.zeros(n_rings),
        predicted=np.zeros((n_rings, n_nodes, 2)),
        edge_length=np.zeros(n_nodes),
        box=np.zeros((n_rings, 4)),
        margin=np.zeros(n_rings),
        order=np.arange(n_rings, dtype=np.int64),
        pairs=np.zeros((max(1, n_rings * (n_rings - 1) // 2), 2), dtype=np.int64),
        contacts=np.zeros((n_rings * n_nodes * min(CONTACTS_PER_NODE, max(1, n_rings - 1)), CONTACT_COLUMNS)),
        orientation=np.ones(n_rings),
        velocity=np.zeros((n_rings, 3)),
    )


def empty_state(n_rings, n_nodes):
    """A zeroed State with every node free."""
    shape = (n_rings, n_nodes, 2)
    return State(
        x=np.zeros(shape),
        v=np.zeros(shape),
        a=np.zeros(shape),
        active=np.full((n_rings, n_nodes), -1, dtype=np.int64),
        contact_force=np.zeros(shape),
        energy=np.zeros((n_rings, ENERGY.size)),
    )


def empty_recording(capacity, n_rings, n_nodes, event_capacity):
    """Uninitialised output buffers for ``capacity`` records."""
    shape = (capacity, n_rings, n_nodes, 2)
    return Recording(
        t=np.empty(capacity),
        x=np.empty(shape),
        v=np.empty(shape),
        pressure=np.empty((capacity, n_rings)),
        contact_force=np.empty(shape),
        events=np.empty((event_capacity, EVENT.size)),
    )


def rings_view(record, start, stop):
    """``record`` (a :class:`Model`, :class:`State` or :class:`Drive`) restricted to rings
    ``[start, stop)``: views of its per-ring fields (``PER_RING_FIELDS`` of a Model, every field of a
    State or Drive), the rest shared. Compiled from the field lists, so a field added to a record is
    sliced or shared by name."""


def _per_ring_fields(cls):
    return PER_RING_FIELDS if cls is Model else cls._fields


@overload(rings_view)
def _rings_view(record, start, stop):
    if not isinstance(record, types.BaseNamedTuple) or record.instance_class not in (Model, State, Drive):
        return None
    cls = record.instance_class
    sliced = _per_ring_fields(cls)
    args = ", ".join(f"record.{f}[start:stop]" if f in sliced else f"record.{f}" for f in cls._fields)
    scope = {"cls": cls}
    exec(f"def impl(record, start, stop):\n    return cls({args})", scope)  # noqa: S102 - fields only
    return scope["impl"]
