"""Tickets for the threaded env step: a counter that threads running compiled code at the same time
draw numbers from, each draw getting a number no other draw gets.

A draw is one atomic fetch-and-add (LLVM's ``atomicrmw add``, sequentially consistent) on an int64
array element, so it needs neither the GIL nor a lock: the threads of a vector step draw the chunks
of envs they step inside one compiled call each (:func:`ballenv.envs.batch.step_batch`) instead of
returning to Python for every chunk. numba has no atomic operations of its own; this is the one the
step needs, written as a numba intrinsic.
"""

from numba import types
from numba.core import cgutils
from numba.extending import intrinsic


@intrinsic
def draw_ticket(typingctx, counter):
    """``counter[0]``, and add 1 to it, in one atomic operation: draws by threads at the same time
    get distinct, consecutive numbers. ``counter``: an int64 array; the caller sets ``counter[0]``
    to the first ticket before the threads start."""
    if not (isinstance(counter, types.Array) and counter.dtype == types.int64):
        return None

    def codegen(context, builder, signature, args):
        array_type = signature.args[0]
        array = context.make_array(array_type)(context, builder, args[0])
        first = context.get_constant(types.intp, 0)
        pointer = cgutils.get_item_pointer(context, builder, array_type, array, [first])
        one = context.get_constant(types.int64, 1)
        return builder.atomic_rmw("add", pointer, one, "seq_cst")

    return types.int64(counter), codegen
