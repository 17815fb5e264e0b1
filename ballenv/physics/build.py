"""The one builder: a :class:`~ballenv.physics.scene.Scene` -> the records the step works on.

:func:`build` makes what every run of a scene needs, for ``Simulation`` and for the env's batch
alike: the model (:func:`build_model`: per-ring arrays and scene scalars, the effects'
parameters; :func:`tiled_model` repeats a one-ring scene's for a batch of independent copies), the
integrator's solver, and the state and trial state. :func:`simulation_workspace` is the scratch of
a whole scene's step, :func:`build_workspace` any other; the ``build_*`` and ``empty_*`` functions
allocate the remaining records, :func:`initial_state` gives the rings' nodes at t = 0, and
:func:`scene_effects` names the effects a scene switches on. Data flows one way: scene -> model
and state -> step.
"""

import math
from collections.abc import Callable, Sequence
from types import ModuleType
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from .base import ring as ring_geometry
from .base.layout import ENERGY, EVENT, PUSH, PUSH_T_END, RAMP, RAMP_T_END, TALLY
from .base.linalg import BAND_COLUMNS, MAX_LOW_RANK, SOLVE_COLUMNS, zigzag_positions
from .effects import EFFECTS
from .effects.assembly import effect_modules, energy_parts, field_name, parameter_table, ring_energy
from .effects.damping import DAMPING_CENTRE_OF_MASS, DAMPING_NONE, DAMPING_RIGID
from .ground import contact as ground_contact
from .ground.motion import ground_array, grounds_move, surface_array
from .model import (
    CONTACT_MASS_MODIFICATION,
    CONTACT_NONE,
    CONTACT_PREDICTOR_CORRECTOR,
    PER_RING_FIELDS,
    BarrierWorkspace,
    CollisionWorkspace,
    DoublingWorkspace,
    Drive,
    Model,
    Recording,
    RingContactWorkspace,
    State,
    Workspace,
)
from .scene import Scene
from .step.contact_error import LIFTOFF_IMPULSE, SCALE_GRAVITY
from .step.integrator import Solver, build_solver
from .walls import impulses
from .walls.impulses import CONTACT_COLUMNS, CONTACTS_PER_NODE
from .walls.ring_barrier import ENTRIES_PER_PAIR, PAIR_COLUMNS, pairs_per_node
from .walls.ring_barrier import PAIRS_PER_NODE as RING_PAIRS_PER_NODE
from .walls.self_barrier import PAIRS_PER_NODE


class Built(NamedTuple):
    """A scene built for its step (:func:`build`)."""

    model: Model
    solver: Solver
    state: State  # the last accepted state of every ring, zeroed
    trial: State  # the trial step's state, zeroed


def build(scene: Scene, effects: Sequence[ModuleType] = EFFECTS, copies: int | None = None) -> Built:
    """``scene``'s model for the forces of ``effects`` (:func:`build_model`), its solver
    (``step.integrator.build_solver``) and a zeroed state and trial state of its rings. With
    ``copies`` = E, the model of E independent copies of the scene's one ring (:func:`tiled_model`:
    the env's batch, one copy per env) and states of E rings."""
    model = build_model(scene, effects)
    if copies is not None:
        model = tiled_model(model, copies)
    n_rings, n_nodes = len(model.node_mass), scene.rings[0].n_nodes
    return Built(model, build_solver(scene), empty_state(n_rings, n_nodes), empty_state(n_rings, n_nodes))


def tiled_model(model: Model, copies: int) -> Model:
    """``model`` of a one-ring scene with its per-ring arrays (``PER_RING_FIELDS``) repeated for
    ``copies`` independent copies (their rings never meet: this is not a scene of many rings)."""
    tiled: dict[str, Any] = {f: np.repeat(getattr(model, f), copies, axis=0) for f in PER_RING_FIELDS}
    return model._replace(**tiled)


def simulation_workspace(
    scene: Scene, model: Model, solver: Solver, effects: Sequence[ModuleType] = EFFECTS
) -> Workspace:
    """The scratch of a whole scene's step (:func:`build_workspace`): the self-contact barrier's,
    the ring pairs' and the joint step's parts where the model asks for them, a row per ground, and
    step doubling's where error control doubles steps in contact (``Scene.contact_error``)."""
    return build_workspace(
        scene.rings[0].n_nodes,
        len(scene.rings),
        effects,
        barrier=model.self_barrier,
        ring_pairs=model.collide,
        ring_contact=model.ring_barrier,
        contact_pairs_per_node=pairs_per_node(model),
        n_grounds=len(scene.grounds) + len(scene.drums),
        doubling=solver.rtol > 0.0
        and scene.contact_error == "doubling"
        and model.contact_method != CONTACT_NONE,
    )


def build_model(scene, effects=EFFECTS):
    """Per-ring arrays and scene scalars of ``scene`` for the forces of ``effects`` (the registry by
    default; :func:`effects.assembly.check_effects` checks that their low-rank Jacobian columns fit
    ``base.linalg.MAX_LOW_RANK``), with their own parameters (``effect_parameters``, whose record dtype
    names the effects: see :mod:`ballenv.physics.effects.assembly`)."""
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
    (:func:`walls.self_barrier.stiffness`, :mod:`ballenv.physics.walls.wall_limits`,
    :func:`walls.ring_barrier.pair_stiffness`)."""
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
    there the contact errors of :mod:`ballenv.physics.step.contact_error` control the step in contact, and
    this bound only what they cannot see (a node released a step early)."""
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
    held (``step.actuation.hold_gas``) before a ramp starts from it."""
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
    candidate pairs, :func:`walls.ring_barrier.pairs_per_node`), else None. A step compiled with None in any
    of these places holds none of that code (numba prunes ``if ... is None`` on an argument before
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
        left=np.zeros(n_rings),
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
        left=np.zeros(n_rings),
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


def initial_state(scene: Scene) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Node positions and velocities (R, N, 2) of the scene's rings at t = 0."""
    pairs = [ring_geometry.initial_nodes(r) for r in scene.rings]
    return np.stack([p[0] for p in pairs]), np.stack([p[1] for p in pairs])


class Constraint(NamedTuple):
    name: str
    enabled: Callable[[Scene], bool]


CONSTRAINTS = (
    Constraint("ground", ground_contact.ground_enabled),
    Constraint("friction", ground_contact.friction_enabled),
    Constraint("ring_collision", impulses.enabled),
)


def scene_effects(scene: Scene, effects: Sequence[ModuleType] = EFFECTS) -> tuple[str, ...]:
    """Names of the effects ``scene`` switches on, forces first, in registry order."""
    names = [e.NAME for e in effects if e.enabled(scene)]
    return tuple(names + [c.name for c in CONSTRAINTS if c.enabled(scene)])
