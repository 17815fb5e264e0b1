"""The records the compiled step works on, declared once by name (SI units).

``Model`` holds the physics (per-ring arrays of length R and scene scalars), ``State`` what the
stepper carries from step to step, ``Workspace`` the scratch arrays of one ring's Newton solve
(``step.integrator.Solver`` holds the numerical method), ``Drive`` actuation spread over time,
``Recording`` the output buffers. All are NamedTuples of NumPy arrays and scalars: numba compiles
them as records, they pickle, and they hold nothing else. :mod:`ballenv.physics.build` makes them
from a :class:`~ballenv.physics.scene.Scene`; :func:`rings_view` slices a record to some rings.
"""

from typing import NamedTuple

import numpy as np
from numba.extending import overload

from .base.record_ref import is_record

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
    """Actuation spread over time (``step/actuation.py``), per ring: a gas ramp and a spread impulse.

    ``step.stepper.advance`` takes it as its own argument: None unless something asks for it
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
    """Scratch of the ring-ring collision code (``walls/impulses.py``) for R rings of N nodes."""

    kicked: np.ndarray  # (R, N, 2) m/s: start velocities of the step after the collision impulses
    kinetic_change: np.ndarray  # (R,) J: change of each ring's kinetic energy by those impulses
    predicted: np.ndarray  # (R, N, 2) m: x0 + h v0, where the step's contacts are found
    edge_length: np.ndarray  # (N,) m: a ring's edge lengths at the predicted positions
    box: np.ndarray  # (R, 4) m: xmin, ymin, xmax, ymax
    margin: np.ndarray  # (R,) m: growth of each box in the broad phase
    order: np.ndarray  # (R,) int64: rings by the left edge of their grown box
    left: np.ndarray  # (R,) m: the left edge of each ring's grown box
    pairs: np.ndarray  # (R (R - 1) / 2, 2) int64: ring pairs of the broad phase
    contacts: np.ndarray  # (C, CONTACT_COLUMNS)
    orientation: np.ndarray  # (R,): +1 counter-clockwise ring, -1 clockwise
    velocity: np.ndarray  # (R, 3): centre-of-mass velocity (m/s), largest node speed relative to it


class BarrierWorkspace(NamedTuple):
    """Scratch of a ring's self-contact barrier (``walls/self_barrier.py``) for rings of N nodes."""

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
    """Scratch of the joint Newton step of rings in contact (``walls/ring_barrier.py``,
    ``step/joint_newton.py``) for R rings of N nodes; ``C`` coupling columns at most, ``P``
    candidate pairs."""

    mode: np.ndarray  # (1,) int64: step.newton.PLAIN (rings one by one) or COUPLED (jointly)
    pairs: np.ndarray  # (P, PAIR_COLUMNS) int64: ring a, node i, ring b, edge j
    n_pairs: np.ndarray  # (1,) int64
    box: np.ndarray  # (R, 4) m: each ring's box over a motion
    margin: np.ndarray  # (R,) m: its growth in the broad phase (the wall thickness)
    order: np.ndarray  # (R,) int64: rings by the left edge of their grown box
    left: np.ndarray  # (R,) m: the left edge of each ring's grown box
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
    doubling: "DoublingWorkspace | None"  # None: no step doubling in contact (``step/contact_error.py``)


class State(NamedTuple):
    x: np.ndarray  # (R, N, 2) m
    v: np.ndarray  # (R, N, 2) m/s
    a: np.ndarray  # (R, N, 2) m/s^2 (the generalized-alpha acceleration)
    active: np.ndarray  # (R, N) int64: constraining ground of each node, or -1
    contact_force: np.ndarray  # (R, N, 2) N
    energy: np.ndarray  # (R, ENERGY.size) J: each ring's energy, its free part and its budget (layout.ENERGY)


class DoublingWorkspace(NamedTuple):
    """The two half steps of a step in contact, whose difference from the whole step is its contact
    error (``step/contact_error.py``)."""

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


def rings_view(record, start, stop):
    """``record`` (a :class:`Model`, :class:`State` or :class:`Drive`) restricted to rings
    ``[start, stop)``: views of its per-ring fields (``PER_RING_FIELDS`` of a Model, every field of a
    State or Drive), the rest shared. Compiled from the field lists, so a field added to a record is
    sliced or shared by name."""


def _per_ring_fields(cls):
    return PER_RING_FIELDS if cls is Model else cls._fields


@overload(rings_view)
def _rings_view(record, start, stop):
    if not is_record(record) or record.instance_class not in (Model, State, Drive):
        return None
    cls = record.instance_class
    sliced = _per_ring_fields(cls)
    args = ", ".join(f"record.{f}[start:stop]" if f in sliced else f"record.{f}" for f in cls._fields)
    scope = {"cls": cls}
    exec(f"def impl(record, start, stop):\n    return cls({args})", scope)  # noqa: S102 - fields only
    return scope["impl"]
