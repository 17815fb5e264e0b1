"""A ring's total force, Jacobian and energy, derived from a list of effects when numba compiles.

A :class:`Model` carries its list of effects in its numba type: its per-ring table
``effect_parameters`` has a record dtype with one field per effect module, in order, named by the
module and holding that effect's own parameters (an empty field for an effect without any; see
:func:`parameter_table`). The generic kernels :func:`ring_force`, :func:`ring_jacobian` and
:func:`ring_energy` are unrolled at compile time into straight calls, one per effect, each behind
the effect's ``on`` test: an effect that is off costs one branch, and the list's order is the order
of the sum. A model of another list (the registry plus a new force, say) compiles its own
specialisation and caches it under its own type. (A dtype, not a Python object, keeps numba's fast
argument typing: a call from Python costs about a microsecond, not forty.)
"""

import importlib

import numpy as np
from numba import types
from numba.extending import overload

from ..base.jit import kernel
from ..base.linalg import MAX_LOW_RANK
from ..base.record_ref import is_record
from . import EFFECTS

NO_PARAMETERS = np.zeros(0)  # ``p`` of an effect without parameters of its own (a compiled constant)


def check_effects(effects):
    """Raise ValueError when the low-rank Jacobian columns of ``effects`` do not fit
    ``base.linalg.MAX_LOW_RANK`` or an energy part appears twice."""
    rank = sum(e.LOW_RANK for e in effects)
    if rank > MAX_LOW_RANK:
        raise ValueError(
            f"effects {[e.NAME for e in effects]} need {rank} low-rank Jacobian columns: "
            f"linalg.MAX_LOW_RANK = {MAX_LOW_RANK}"
        )
    parts = [e.ENERGY_PART for e in effects if e.ENERGY_PART is not None]
    if len(set(parts)) != len(parts) or "kinetic" in parts:
        raise ValueError(f"energy parts {parts} must be distinct and not 'kinetic'")


def field_name(k, effect):
    """Name of the ``k``-th effect's field in ``Model.effect_parameters``: ``"k module"`` (the
    position is in the name: numba orders a record's fields by offset, and empty fields share one)."""
    return f"{k} {effect.__name__}"


def parameter_table(effects, n_rings):
    """The empty per-ring table of ``effects`` (checked with :func:`check_effects`): ``n_rings``
    records with one field per effect (:func:`field_name`) of ``len(PARAMETERS)`` floats."""
    effects = tuple(effects)
    check_effects(effects)
    fields = [(field_name(k, e), np.float64, (len(e.PARAMETERS),)) for k, e in enumerate(effects)]
    return np.zeros(n_rings, dtype=fields)


def _modules(names):
    """Effect modules, in order, from field names of :func:`field_name` (imported if need be)."""
    ordered = sorted(names, key=lambda name: int(name.split(" ")[0]))
    return tuple(importlib.import_module(name.split(" ")[1]) for name in ordered)


def effect_modules(table):
    """The effect modules of a ``Model.effect_parameters`` table, in order."""
    return _modules(table.dtype.names)


def energy_parts(effects=EFFECTS):
    """Names of the energy table's columns: kinetic, then each effect's ``ENERGY_PART`` in order."""
    return ("kinetic",) + tuple(e.ENERGY_PART for e in effects if e.ENERGY_PART is not None)


ENERGY_PARTS = energy_parts()  # of the registry
ENERGY_KINETIC = 0


# ------------------------------------------------------------------ compile-time unrolled sums
def _effects_of(model):
    """The effect modules of a Model's numba type (the record dtype of ``effect_parameters``)."""
    if not is_record(model) or "effect_parameters" not in model.fields:
        return None
    typ = model.types[model.fields.index("effect_parameters")]
    if not (isinstance(typ, types.Array) and isinstance(typ.dtype, types.Record)):
        return None
    return _modules(name for name, _ in typ.dtype.members)


def _unrolled(effects, signature, body, returns):
    """``impl(signature)`` whose lines are ``body(k, effect)`` per effect, with the effects' kernels
    as globals ``on_k``, ``force_k``, ``jacobian_k``, ``energy_k`` and ``p_k`` their parameters (ring
    ``r``'s field of ``model.effect_parameters``)."""
    scope = {"NO_PARAMETERS": NO_PARAMETERS}
    lines = [f"def impl({signature}):"]
    for k, effect in enumerate(effects):
        for part in ("on", "force", "jacobian", "energy"):
            scope[f"{part}_{k}"] = getattr(effect, part)
        view = (
            f"model.effect_parameters[r][{field_name(k, effect)!r}]" if effect.PARAMETERS else "NO_PARAMETERS"
        )
        lines.append(f"    p_{k} = {view}")
        lines += ["    " + line for line in body(k, effect)]
    lines.append(f"    return {returns}")
    exec("\n".join(lines), scope)  # noqa: S102 - source built above from the effects' list
    return scope["impl"]


def sum_forces(model, r, x, v, f):
    """Add the forces (N) of ``model``'s effects on ring ``r`` into ``f``."""


def sum_jacobians(model, r, x, v, coef_x, coef_v, ws, rank):
    """Add ``coef_x dF/dx + coef_v dF/dv`` of ``model``'s effects; return the new rank."""


def sum_energies(model, r, x, v, parts):
    """Write each effect's energy (J) into ``parts`` (columns of :func:`energy_parts`; kinetic left
    alone); an effect that is off gets 0."""


@overload(sum_forces, inline="always")
def _sum_forces(model, r, x, v, f):
    effects = _effects_of(model)
    if effects is None:
        return None
    return _unrolled(
        effects,
        "model, r, x, v, f",
        lambda k, e: [f"if on_{k}(model, p_{k}, r):", f"    force_{k}(model, p_{k}, r, x, v, f)"],
        "None",
    )


@overload(sum_jacobians, inline="always")
def _sum_jacobians(model, r, x, v, coef_x, coef_v, ws, rank):
    effects = _effects_of(model)
    if effects is None:
        return None
    return _unrolled(
        effects,
        "model, r, x, v, coef_x, coef_v, ws, rank",
        lambda k, e: [
            f"if on_{k}(model, p_{k}, r):",
            f"    rank = jacobian_{k}(model, p_{k}, r, x, v, coef_x, coef_v, ws, rank)",
        ],
        "rank",
    )


@overload(sum_energies, inline="always")
def _sum_energies(model, r, x, v, parts):
    effects = _effects_of(model)
    if effects is None:
        return None
    columns = energy_parts(effects)

    def body(k, effect):
        if effect.ENERGY_PART is None:
            return []
        c = columns.index(effect.ENERGY_PART)
        return [f"parts[{c}] = energy_{k}(model, p_{k}, r, x, v) if on_{k}(model, p_{k}, r) else 0.0"]

    return _unrolled(effects, "model, r, x, v, parts", body, "None")


def gravity_column(model):
    """Column of the gravity energy in ``model``'s energy parts, or -1 without gravity."""


@overload(gravity_column)
def _gravity_column(model):
    effects = _effects_of(model)
    if effects is None:
        return None
    parts = energy_parts(effects)
    column = parts.index("gravity") if "gravity" in parts else -1
    return lambda model: column


# ------------------------------------------------------------------------------- a ring's sums
@kernel
def ring_force(model, r, x, v, f):
    """Total force (N) on the nodes of ring ``r``, written to ``f``; only the effects that are on."""
    f[:, :] = 0.0
    sum_forces(model, r, x, v, f)


@kernel
def ring_jacobian(model, r, x, v, c_mass, c_x, c_v, ws):
    """Assemble ``c_M M - c_x dF/dx - c_v dF/dv`` as band ``ws.band`` + ``ws.u ws.w^T``; return rank."""
    band = ws.band
    pos = ws.pos
    band[:, :] = 0.0
    diag = c_mass * model.node_mass[r]
    w = (band.shape[1] - 1) // 2
    for i in range(x.shape[0]):
        p = 2 * pos[i]
        band[p, w] += diag
        band[p + 1, w] += diag
    return sum_jacobians(model, r, x, v, -c_x, -c_v, ws, 0)


@kernel
def ring_energy(model, r, x, v, parts):
    """Energy (J) of ring ``r`` by part into ``parts`` (columns :func:`energy_parts` of the model's
    effects); returns their sum."""
    kinetic = 0.0
    for i in range(x.shape[0]):
        kinetic += v[i, 0] * v[i, 0] + v[i, 1] * v[i, 1]
    parts[ENERGY_KINETIC] = 0.5 * model.node_mass[r] * kinetic
    sum_energies(model, r, x, v, parts)
    return parts.sum()
