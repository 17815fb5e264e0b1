"""numba's inlining of an ``inline="always"`` kernel without the two copies of IR made for that one
call site.

At each call of a function compiled with ``inline="always"``, numba's
``InlineWorker.inline_function`` translates the callee to IR afresh (its untyped passes) and hands
that IR to ``InlineWorker.inline_ir``, which deep-copies every block of it twice: once because it
relabels, renames and splices the blocks it inlines in place (the IR it is given may be shared, as an
overload's IR kept for every call site is), and once more for an untouched copy it returns, which
every caller in numba discards. The IR ``inline_function`` made is used by that call site alone, so
copying it protects nothing.

:func:`install` wraps ``inline_function``: while ``inline_ir`` runs, the new IR's blocks are their
own deep copy (:class:`_OwnCopy`), and after it they are numba's ``ir.Block`` again, so any later
copy of the caller's IR copies them as before. ``inline_ir`` itself, and the inlining of overloads
through it (their IR is shared), are numba's own.
"""

from numba.core import ir
from numba.core.inline_closurecall import InlineWorker


class _OwnCopy(ir.Block):
    """An IR block whose deep copy is itself: a block of IR made for one call site."""

    def __deepcopy__(self, memo):
        return self


def _inline_function(self, caller_ir, block, i, function, arg_typs=None):
    """``InlineWorker.inline_function`` without copying the IR it makes (module doc)."""
    callee_ir = self.run_untyped_passes(function)
    fresh = list(callee_ir.blocks.values())
    for b in fresh:
        b.__class__ = _OwnCopy
    try:
        freevars = function.__code__.co_freevars
        return self.inline_ir(caller_ir, block, i, callee_ir, freevars, arg_typs=arg_typs)
    finally:
        for b in (*fresh, *caller_ir.blocks.values()):
            if type(b) is _OwnCopy:
                b.__class__ = ir.Block


_numba_inline_function = InlineWorker.inline_function


def install():
    """Make the copy-free inlining numba's (idempotent)."""
    InlineWorker.inline_function = _inline_function
