"""Records passed to compiled code by reference (``record_ref.py``) read as their NamedTuples do."""

import pickle
from typing import NamedTuple

import numba
import numpy as np
import pytest
from llvmlite import ir
from numba import njit
from numba.core.registry import cpu_target

from ballenv.physics import Ground, Ring, Scene, Simulation
from ballenv.physics.base import record_ref
from ballenv.physics.base.record_ref import RecordRef, is_record, reference
from ballenv.physics.model import rings_view


class Inner(NamedTuple):
    counts: np.ndarray
    scale: float


class Outer(NamedTuple):
    x: np.ndarray  # (3, 2) float64
    column: np.ndarray  # a strided view
    flags: np.ndarray  # bool
    ids: np.ndarray  # int64
    h: float
    n: int
    on: bool
    off: bool
    missing: None
    inner: Inner


@njit(_nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _read(r):
    """Every field of an ``Outer``, reduced to one float, and one write through ``r.ids``."""
    s = r.x[2, 1] + r.column[1] + r.h + r.n + r.inner.scale + r.inner.counts[1]
    s += 1000.0 if r.on else 0.0
    s += 2000.0 if r.off else 0.0
    s += 4000.0 if r.flags[1] else 0.0
    s += 8000.0 if r.missing is None else 0.0
    r.ids[0] += 1
    return s + r.x.shape[0] + r.column.strides[0]


@njit(_nrt=False)
def read(r):
    return _read(r)


def _outer():
    base = np.arange(12.0).reshape(4, 3)
    return Outer(
        x=np.arange(6.0).reshape(3, 2), column=base[:, 1], flags=np.array([False, True]),
        ids=np.array([5, 6]), h=0.25, n=7, on=True, off=False, missing=None,
        inner=Inner(counts=np.array([3, 4]), scale=-1.5),
    )  # fmt: skip


def test_compiled_code_reads_every_kind_of_field_of_a_record_ref_as_of_its_named_tuple():
    by_value, by_reference = _outer(), _outer()
    ref = RecordRef(by_reference)
    assert read(ref) == read(by_value)
    assert read(ref) == 5.0 + 4.0 + 0.25 + 7 + -1.5 + 4 + 1000.0 + 4000.0 + 8000.0 + 3 + 24
    # writes reach the record's own arrays: two calls by reference, one by value
    assert (by_reference.ids[0], by_value.ids[0]) == (7, 6)


def test_a_record_ref_passes_one_pointer_where_a_named_tuple_passes_every_array():
    record = _outer()
    read(RecordRef(record))
    read(record)
    by_type = {str(sig[0]).split("(")[0]: sig for sig in _read.signatures}
    assert set(by_type) == {f"RecordRef.{__name__}.Outer", "Outer"}
    ref_type = RecordRef(record).numba_type
    models = cpu_target.target_context.data_model_manager
    assert models[ref_type].get_value_type() == ir.IntType(8).as_pointer()  # one pointer
    assert len(models[numba.typeof(record)].get_value_type().elements) == len(Outer._fields)
    assert is_record(ref_type) and ref_type.instance_class is Outer
    assert ref_type.fields == Outer._fields
    assert ref_type.offsets["column"] == (5 + 2 * 2) * record_ref.WORD  # after x's descriptor
    assert RecordRef(record).buffer.size * record_ref.WORD == ref_type.offsets["inner"] + record_ref.WORD


@njit(_nrt=False)
def _fields(r):
    return r.x, r.inner.counts


def test_a_kernel_returns_field_arrays_of_a_record_ref_as_the_arrays_themselves():
    """numba without reference counting returns an array's parent: the Python array it came from."""
    outer = _outer()
    for record in (outer, RecordRef(outer)):
        x, counts = _fields(record)
        assert x is outer.x and counts is outer.inner.counts


def test_a_pickled_record_ref_points_at_its_own_copies_of_the_arrays():
    record = _outer()
    copy = pickle.loads(pickle.dumps(RecordRef(record)))
    assert copy.address != RecordRef(record).address
    copy.record.x[2, 1] = 100.0
    assert record.x[2, 1] == 5.0
    unpickled = pickle.loads(pickle.dumps(_outer()))  # its strided view comes back contiguous
    assert read(copy) == read(unpickled) + 95.0


def test_reference_makes_one_record_ref_per_record_and_keeps_a_bounded_number():
    record = _outer()
    assert reference(record) is reference(record)
    assert reference(record).record is record
    others = [_outer() for _ in range(record_ref.HELD + 1)]
    for other in others:
        reference(other)
    assert len(record_ref._held) == record_ref.HELD
    assert id(record) not in record_ref._held  # the oldest, let go


def test_a_field_of_no_known_layout_is_refused_by_name():
    class Odd(NamedTuple):
        name: str

    with pytest.raises(TypeError, match="field of type str"):
        RecordRef(Odd("a"))


def test_a_simulation_passes_its_records_by_reference_and_rings_views_accept_them():
    sim = Simulation(Scene(rings=[Ring(n_nodes=16, position=(0.0, 0.3))], grounds=[Ground()]))
    assert sim.advance(0.01)
    model = reference(sim.model)
    assert is_record(model.numba_type)
    view = _ring_radius(model, 0)
    assert view == sim.model.radius[0]


@njit(_nrt=False)
def _ring_radius(model, r):
    return rings_view(model, r, r + 1).radius[0]
