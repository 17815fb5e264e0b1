"""A call's type resolved once per argument types (``ballenv.physics.base.call_types``): the memo
gives numba's own signature, searches numba's templates once per key, and leaves failures to raise."""

import operator

import pytest
from numba.core import errors, types
from numba.core.registry import cpu_target
from numba.core.types import functions

from ballenv.physics.base import call_types, jit  # noqa: F401  (jit installs the memo)

MATRIX = types.Array(types.float64, 2, "C")
INDEX = types.UniTuple(types.intp, 2)


def _getitem():
    context = cpu_target.typing_context
    context.refresh()
    return context, context.resolve_value_type(operator.getitem)


def test_the_memoised_resolution_is_numbas():
    assert functions.BaseFunction.get_call_type is call_types._resolve


def test_a_resolution_gives_numbas_signature_and_searches_the_templates_once(monkeypatch):
    context, getitem = _getitem()
    searches, numba_own = [], call_types._numba_get_call_type

    def numba_search(self, ctx, args, kws):
        searches.append(args)
        return numba_own(self, ctx, args, kws)

    monkeypatch.setattr(call_types, "_memo", {})
    monkeypatch.setattr(call_types, "_numba_get_call_type", numba_search)
    first = getitem.get_call_type(context, (MATRIX, INDEX), {})
    second = getitem.get_call_type(context, (MATRIX, INDEX), {})
    own = numba_own(getitem, context, (MATRIX, INDEX), {})
    assert first == second == own and first.return_type == types.float64
    assert first is not second  # a copy each time: a caller may change its own
    assert searches == [(MATRIX, INDEX)]  # the two calls searched once
    vector = getitem.get_call_type(context, (MATRIX, types.intp), {})  # a row: other types, a search
    assert vector.return_type == types.Array(types.float64, 1, "C") and len(searches) == 2


def test_literal_argument_types_are_keys_of_their_own(monkeypatch):
    context = cpu_target.typing_context
    add = context.resolve_value_type(operator.add)
    monkeypatch.setattr(call_types, "_memo", {})
    literal = add.get_call_type(context, (types.IntegerLiteral(3), types.int64), {})
    plain = add.get_call_type(context, (types.int64, types.int64), {})
    assert len(call_types._memo) == 2 and literal.return_type == plain.return_type == types.int64


def test_a_failed_resolution_is_not_memoised_and_raises_each_time(monkeypatch):
    context, getitem = _getitem()
    monkeypatch.setattr(call_types, "_memo", {})
    for _ in range(2):
        with pytest.raises(errors.TypingError):
            getitem.get_call_type(context, (types.float64, types.float64), {})
    assert call_types._memo == {}
