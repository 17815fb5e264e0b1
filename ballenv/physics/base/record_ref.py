"""A record of arrays passed to compiled code by reference: :class:`RecordRef`, one pointer.

numba passes a NamedTuple of arrays (``Model``, ``State``, ``Workspace``) by value: every array's
data pointer, shape and strides become arguments of every call, unpacked in the caller and packed
again in the callee. For records of 20-60 arrays that is most of the IR numba lowers and LLVM
optimises for each kernel, and the compile time grows with the record's size
(``benchmarks/record_passing.py``). A :class:`RecordRef` holds the same record and one buffer of
its fields as numba lays them out (an array's descriptor: meminfo, parent, size, item size, data
pointer, shape, strides; a scalar's value; a nested record's buffer address; nothing for None).
Compiled code gets the buffer's address and reads a field where it is used, so a kernel's field
reads (``model.ei``, ``ws.barrier is None``) compile as for the NamedTuple, to the same values.

The kernels compile without reference counting (``jit.py``), so the descriptors carry no meminfo
(and as parent the array's own Python object, which such a kernel returns for the array, as for the
NamedTuple): the RecordRef keeps every array alive, and the caller keeps the RecordRef alive for
the call. The buffer is read-only to compiled code (loads marked invariant); a record whose arrays
are replaced needs a new RecordRef (:func:`reference` makes one per record object).
"""

import threading
from collections import OrderedDict
from typing import Any

import numpy as np
from llvmlite import ir  # type: ignore[import-untyped]
from numba import typeof
from numba.core import types
from numba.core.typing.templates import AttributeTemplate
from numba.extending import (
    NativeValue,
    infer_getattr,
    lower_getattr_generic,
    models,
    register_model,
    typeof_impl,
    unbox,
)

WORD = 8  # bytes of one slot of the buffer: every field starts on a multiple of it


class RecordRefType(types.Type):
    """numba's type of a :class:`RecordRef` of NamedTuple class ``instance_class`` whose fields have
    the numba types ``field_types`` (in order): the same field names and types as the NamedTuple's
    own type, so overloads that read ``fields``, ``types`` and ``instance_class`` accept both."""

    def __init__(self, instance_class: type, field_types: tuple) -> None:
        self.instance_class = instance_class
        self.fields: tuple[str, ...] = tuple(getattr(instance_class, "_fields"))  # noqa: B009 - a NamedTuple class
        self.types = tuple(field_types)
        self.offsets = {}
        offset = 0
        for name, typ in zip(self.fields, self.types, strict=True):
            self.offsets[name] = offset
            offset += _slots(typ) * WORD
        listed = ", ".join(f"{n}: {t}" for n, t in zip(self.fields, self.types, strict=True))
        super().__init__(
            name=f"RecordRef.{instance_class.__module__}.{instance_class.__qualname__}({listed})"
        )


def _slots(typ: types.Type) -> int:
    """Words of the buffer a field of numba type ``typ`` takes."""
    if isinstance(typ, types.Array):
        return 5 + 2 * typ.ndim
    return 0 if isinstance(typ, types.NoneType) else 1


def is_record(typ: Any) -> bool:
    """Whether numba type ``typ`` is a record: a NamedTuple's or a :class:`RecordRef`'s."""
    return isinstance(typ, types.BaseNamedTuple | RecordRefType)


class RecordRef:
    """``record`` (a NamedTuple of arrays, scalars, None and such records) for compiled code, by
    reference. ``record`` is the NamedTuple itself; :attr:`address` the buffer's."""

    def __init__(self, record: Any) -> None:
        self.record = record
        self.nested = []  # the RecordRefs of nested records, kept alive with this one
        words: list[int] = []
        field_types = []
        for value in record:
            if isinstance(value, tuple) and hasattr(value, "_fields"):
                value = RecordRef(value)
                self.nested.append(value)
            field_types.append(typeof(value))
            words += _words(value)
        self.buffer = np.array(words, dtype=np.uint64)
        self.address = self.buffer.ctypes.data
        self.numba_type = RecordRefType(type(record), tuple(field_types))

    def __reduce__(self):
        """Pickled as its record: the addresses are made again where it is loaded."""
        return RecordRef, (self.record,)


def _words(value: Any) -> list[int]:
    """The buffer's words of one field ``value``, laid out as numba's data model of its type."""
    if isinstance(value, np.ndarray):
        shape = [int(s) for s in value.shape]
        strides = [int(s) % 2**64 for s in value.strides]
        # no meminfo; the parent is the array's own Python object, what a kernel compiled without
        # reference counting returns for an array (numba's box_array), as for the NamedTuple
        return [0, id(value), value.size, value.itemsize, value.ctypes.data, *shape, *strides]
    if isinstance(value, RecordRef):
        return [value.address]
    if value is None:
        return []
    if isinstance(value, bool | np.bool_):
        return [int(value)]  # numba's boolean is one byte; little-endian, it is the word's first
    if isinstance(value, float | np.floating):
        return [int(np.float64(value).view(np.uint64))]
    if isinstance(value, int | np.integer):
        return [int(value) % 2**64]
    raise TypeError(f"RecordRef: a field of type {type(value).__name__} has no layout")


HELD = 64  # RecordRefs kept for the records last passed


_held: "OrderedDict[int, RecordRef]" = OrderedDict()
_lock = threading.Lock()


def reference(record: Any) -> RecordRef:
    """The :class:`RecordRef` of ``record``, made on its first call and kept while it is among the
    last ``HELD`` records passed (a kept RecordRef holds its record, so ``id(record)`` is not
    reused while it is kept)."""
    with _lock:  # callers on several threads may pass records at once
        ref = _held.get(id(record))
        if ref is None or ref.record is not record:
            ref = _held[id(record)] = RecordRef(record)
            if len(_held) > HELD:
                _held.popitem(last=False)
        else:
            _held.move_to_end(id(record))
    return ref


@typeof_impl.register(RecordRef)
def _typeof_record_ref(value, context):
    return value.numba_type


@register_model(RecordRefType)
class _RecordRefModel(models.OpaqueModel):
    """A RecordRef in compiled code: the buffer's address (``i8*``)."""


@infer_getattr
class _RecordRefAttributes(AttributeTemplate):
    key = RecordRefType

    def generic_resolve(self, typ, attr):
        if attr in typ.offsets:
            return typ.types[typ.fields.index(attr)]
        return None


@lower_getattr_generic(RecordRefType)
def _load_field(context, builder, typ, value, attr):
    """Field ``attr`` of the buffer at ``value``: its data model's value, loaded at its offset."""
    field_type = typ.types[typ.fields.index(attr)]
    if isinstance(field_type, types.NoneType):
        return context.get_dummy_value()
    model = context.data_model_manager[field_type]
    where = builder.gep(value, [ir.Constant(ir.IntType(64), typ.offsets[attr])])
    data_type = model.get_data_type()
    pointer = builder.bitcast(where, data_type.as_pointer())
    return model.from_data(builder, _load_scalars(builder, pointer, data_type))


def _load_scalars(builder, pointer, data_type):
    """The value of LLVM type ``data_type`` at ``pointer``, loaded one scalar at a time, each load
    marked invariant (an aggregate's load is split by LLVM's passes, which may drop the mark and
    with it the loads' hoisting out of loops)."""
    if not isinstance(data_type, ir.LiteralStructType | ir.ArrayType):
        loaded = builder.load(pointer)
        loaded.set_metadata("invariant.load", builder.module.add_metadata([]))
        return loaded
    out = ir.Constant(data_type, ir.Undefined)
    count = len(data_type.elements) if isinstance(data_type, ir.LiteralStructType) else data_type.count
    for k in range(count):
        element = data_type.elements[k] if isinstance(data_type, ir.LiteralStructType) else data_type.element
        at = builder.gep(pointer, [ir.Constant(ir.IntType(32), 0), ir.Constant(ir.IntType(32), k)])
        out = builder.insert_value(out, _load_scalars(builder, at, element), k)
    return out


@unbox(RecordRefType)
def _unbox_record_ref(typ, obj, c):
    address = c.pyapi.object_getattr_string(obj, "address")
    pointer = c.pyapi.long_as_voidptr(address)
    c.pyapi.decref(address)
    return NativeValue(pointer)
