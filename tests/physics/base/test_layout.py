"""Layouts declared once by name (``layout.py``, ``model.PER_RING_FIELDS``) and their users agree."""

import numpy as np
from numba import njit

from ballenv.physics import Ground, Ring, Scene, simulate
from ballenv.physics.base import layout
from ballenv.physics.build import build_model, build_workspace, empty_state
from ballenv.physics.effects import EFFECTS
from ballenv.physics.effects.assembly import (
    ENERGY_PARTS,
    NO_PARAMETERS,
    effect_modules,
    energy_parts,
    ring_energy,
    ring_force,
)
from ballenv.physics.model import PER_RING_FIELDS, Model, rings_view


def _constants(prefix):
    return {k: v for k, v in vars(layout).items() if k.startswith(prefix) and isinstance(v, int)}


def test_counter_and_clock_constants_name_every_slot_once_and_fit():
    for prefix, table, size in (
        ("COUNT_", layout.COUNTERS, layout.N_COUNTERS),
        ("CLOCK_", layout.CLOCK, layout.N_CLOCK),
        ("ENERGY_", layout.ENERGY, layout.ENERGY.size),
        ("TALLY_", layout.TALLY, layout.TALLY.size),
        ("STATUS_", layout.STATUS, layout.STATUS.size),
        ("GROUND_", layout.GROUND, layout.GROUND.size),
        ("SURFACE_", layout.SURFACE, layout.SURFACE.size),
    ):
        values = _constants(prefix)
        assert all(0 <= v < size for v in values.values()), (prefix, values)
        assert sorted(values.values()) == sorted(table.index(name) for name in table.names), prefix
    by_reason = layout.COUNTERS.slice("by_reason")
    assert by_reason.stop - by_reason.start == len(layout.REJECTIONS)
    codes = _constants("REJECT_")
    assert sorted(codes.values()) == list(range(1, len(layout.REJECTIONS) + 1))
    assert layout.COUNT_BY_REASON + max(codes.values()) - 1 < layout.COUNT_IMPULSE_REJECTED


def test_layout_rejects_a_name_declared_twice():
    try:
        layout.Layout("steps", ("steps", 2))
    except ValueError as exc:
        assert "steps" in str(exc)
    else:
        raise AssertionError("a repeated name must raise")


def test_stats_report_every_rejection_reason_of_the_layout():
    scene = Scene(rings=[Ring(n_nodes=16)], grounds=[Ground()], adaptive=True, dt=1e-2, impulse_tol=1e-3)
    stats = simulate(scene, 0.6).stats
    assert list(stats.rejections) == [*layout.REJECTIONS, "impulse", "error"]
    assert sum(stats.rejections.values()) == stats.rejected_steps > 0


def test_energy_parts_come_from_the_effects_and_size_the_workspace():
    assert ENERGY_PARTS == ("kinetic",) + tuple(e.ENERGY_PART for e in EFFECTS if e.ENERGY_PART)
    assert build_workspace(8).energy.shape == (len(energy_parts()),)
    assert empty_state(2, 8).energy.shape == (2, layout.ENERGY.size)


def _model(n_rings):
    rings = [
        Ring(n_nodes=8, position=(0.5 * k, 1.0), pressure=(None if k % 2 else 1e4)) for k in range(n_rings)
    ]
    return build_model(Scene(rings=rings, grounds=[Ground(), Ground(angle=0.2)]))


def test_per_ring_fields_are_exactly_the_fields_with_one_row_per_ring():
    """A Model field added with one entry per ring but not declared in PER_RING_FIELDS (or the
    reverse) fails here: the env's per-env view would share it instead of slicing it."""
    three, five = _model(3), _model(5)
    per_ring = {
        name
        for name in Model._fields
        if isinstance(getattr(three, name), np.ndarray)
        and getattr(three, name).shape[:1] == (3,)
        and getattr(five, name).shape[:1] == (5,)
    }
    assert per_ring == set(PER_RING_FIELDS)


@njit(cache=True)
def _view(record, start, stop):
    return rings_view(record, start, stop)


def test_rings_view_slices_per_ring_fields_and_shares_the_rest():
    model = _model(3)
    view = _view(model, 1, 2)
    assert view._fields == model._fields
    for name in Model._fields:
        value, viewed = getattr(model, name), getattr(view, name)
        if name in PER_RING_FIELDS:
            np.testing.assert_array_equal(viewed, value[1:2])
            assert np.shares_memory(viewed, value) or value.nbytes == 0  # (records of no parameters)
        elif isinstance(value, np.ndarray):
            np.testing.assert_array_equal(viewed, value)
            assert np.shares_memory(viewed, value)
        else:
            assert viewed == value
    state = empty_state(3, 8)
    sv = _view(state, 2, 3)
    for name in state._fields:
        assert np.shares_memory(getattr(sv, name), getattr(state, name)[2:3])


def test_each_energy_column_and_force_term_comes_from_its_own_effect_in_registry_order():
    """The compiled sums follow the registry's order: every energy column holds the energy of the
    effect it is named after, and the force is the sum of the effects' forces."""
    scene = Scene(rings=[Ring(n_nodes=12, pressure=2e4)], damping=3.0)
    model = build_model(scene)
    assert effect_modules(model.effect_parameters) == EFFECTS
    rng = np.random.default_rng(1)
    x = Ring(n_nodes=12).radius * np.stack(
        [np.cos(np.arange(12) * np.pi / 6), np.sin(np.arange(12) * np.pi / 6)], axis=1
    ) + 1e-3 * rng.standard_normal((12, 2))
    v = rng.standard_normal((12, 2))
    parts = np.zeros(len(ENERGY_PARTS))
    ring_energy(model, 0, x, v, parts)
    force = np.zeros_like(x)
    ring_force(model, 0, x, v, force)
    total = np.zeros_like(x)
    for effect in EFFECTS:
        if effect.ENERGY_PART is not None:
            own = effect.energy(model, NO_PARAMETERS, 0, x, v)
            assert parts[ENERGY_PARTS.index(effect.ENERGY_PART)] == own, effect.NAME
        effect.force(model, NO_PARAMETERS, 0, x, v, total)
    np.testing.assert_array_equal(force, total)
