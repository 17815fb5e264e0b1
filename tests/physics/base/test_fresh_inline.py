"""numba's inlining of ``inline="always"`` functions without copying the IR made for the call site
(``ballenv.physics.base.fresh_inline``)."""

import copy

import numpy as np
from numba import njit
from numba.core import inline_closurecall, ir
from numba.core.inline_closurecall import InlineWorker

from ballenv.physics.base import fresh_inline, jit  # noqa: F401  (jit installs it)


@njit(inline="always")
def _clipped_sum(a, lo, hi):
    s = 0.0
    for k in range(a.size):
        v = a[k]
        if v < lo:
            v = lo
        elif v > hi:
            v = hi
        s += v
    return s


def _caller(a):
    return _clipped_sum(a, -1.0, 1.0) + 2.0 * _clipped_sum(a, 0.0, 0.5)


def _compiled(inline_function, monkeypatch):
    """``_caller`` compiled afresh with ``inline_function`` as numba's; (dispatcher, blocks deep-copied
    while inlining, classes of the caller's blocks after each inline)."""
    copies, classes = [], []

    def counting_deepcopy(x, memo=None):
        y = copy.deepcopy(x, memo)
        if isinstance(x, ir.Block) and y is not x:
            copies.append(x)
        return y

    def inline(self, caller_ir, *args, **kwargs):
        out = inline_function(self, caller_ir, *args, **kwargs)
        classes.extend(type(b) for b in caller_ir.blocks.values())
        return out

    counting_copy = type("CountingCopy", (), {"deepcopy": staticmethod(counting_deepcopy)})
    monkeypatch.setattr(inline_closurecall, "copy", counting_copy)
    monkeypatch.setattr(InlineWorker, "inline_function", inline)
    dispatcher = njit(_caller)
    a = np.linspace(-2.0, 2.0, 9)
    return dispatcher, dispatcher(a), copies, classes


def test_the_inlined_call_computes_what_numbas_own_inlining_does(monkeypatch):
    numba_own, expected, own_copies, _ = _compiled(fresh_inline._numba_inline_function, monkeypatch)
    ours, got, copies, classes = _compiled(fresh_inline._inline_function, monkeypatch)
    assert got == expected == _caller(np.linspace(-2.0, 2.0, 9))
    assert len(own_copies) >= 2 * 2  # numba's own: every block of each inlined call, twice
    assert copies == []
    assert classes and set(classes) == {ir.Block}  # the blocks are numba's own again after inlining
    assert len(ours.overloads) == len(numba_own.overloads) == 1


def test_numba_inlines_through_the_copy_free_inlining():
    assert InlineWorker.inline_function is fresh_inline._inline_function
    fresh_inline.install()
    assert InlineWorker.inline_function is fresh_inline._inline_function


def test_only_a_block_marked_as_its_own_copy_skips_the_deep_copy():
    block = ir.Block(ir.Scope(None, ir.unknown_loc), ir.unknown_loc)
    block.__class__ = fresh_inline._OwnCopy
    assert copy.deepcopy(block) is block
    block.__class__ = ir.Block
    assert copy.deepcopy(block) is not block
