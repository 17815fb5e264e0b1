"""How the simulator's kernels are compiled: :func:`kernel`, numba's ``njit`` with the on-disk cache,
without reference counting, and without the Python wrappers of functions that only compiled code
calls.

numba counts references to every array a compiled function holds: each call of a function that takes
a record of arrays (``Model``, ``State``, ``Workspace``: about 60 arrays) adds one and removes one
per array, each an atomic memory operation, and with threads stepping different envs they contend
for the same cache lines (every thread holds the same model arrays). The kernels allocate nothing:
every array they touch is owned by the Python object that calls them (a ``Simulation``, an env's
batch) for the whole call, so the counts protect nothing. Compiled without them (numba's
``_nrt=False``), a kernel that tries to allocate (``np.empty``, a copying array expression,
returning a new array) does not compile: "NRT required but not enabled" names it.

numba also compiles, with every function, the wrappers that let Python call it: code that unboxes
each argument from a Python object (every array of every record) and boxes the result. For a
function taking the records that is most of its compile time, and most kernels are only ever called
by other kernels. So a kernel is compiled without them (numba's ``no_cpython_wrapper``,
``no_cfunc_wrapper``). Called from Python, a kernel calls its twin (:func:`python_entry`): the same
function compiled with the wrappers, cached under its own name (``<name>.python``), compiled only
for kernels Python calls (``simulate``'s driver, the env's step and reset, a test), and given its
records by reference (:func:`by_reference`). Processes that
compile the same twin for the same argument types at once compile it once (:mod:`.compile_lock`).
Only the twins are turned into machine code; the kernels they call stay LLVM IR, linked into each
twin and optimised there once (:mod:`.machine_code`). Repetitions in numba's own compiler are
done once or not at all: the search for a call's signature (:mod:`.call_types`), the terminal
markup of the errors it makes and catches (:mod:`.error_text`) and the two copies of the IR it
inlines at each call of an ``inline="always"`` kernel (:mod:`.fresh_inline`).
"""

import types

from numba import njit
from numba.core.registry import CPUDispatcher

from . import cache_location, call_types, error_text, fresh_inline, machine_code, record_ref
from .compile_lock import SharedCompile

OPTIONS = {"cache": cache_location.apply(), "_nrt": False}  # no cache only where nothing is writable
WRAPPERS = ("no_cpython_wrapper", "no_cfunc_wrapper")
machine_code.install()
call_types.install()
error_text.install()
fresh_inline.install()


class InnerKernel(CPUDispatcher):
    """A kernel compiled without Python wrappers; called from Python, it calls its twin
    (:func:`python_entry`) with its records by reference (:func:`by_reference`)."""

    def __call__(self, *args, **kwargs):
        args = tuple(by_reference(a) for a in args)
        kwargs = {k: by_reference(v) for k, v in kwargs.items()}
        return python_entry(self)(*args, **kwargs)


def by_reference(value):
    """``value`` as a kernel called from Python takes it: a record (a NamedTuple of arrays,
    scalars, None and records) as its :class:`.record_ref.RecordRef`, a tuple of records as a tuple
    of theirs, anything else as it is. The twin then unboxes one pointer a record, not its every
    array, and compiles for the same types as the kernels that the step passes records by reference
    (one compile of a kernel both call, not one for each)."""
    if not isinstance(value, tuple):
        return value
    if hasattr(value, "_fields"):
        try:
            return record_ref.reference(value)
        except TypeError:  # a field with no layout in a RecordRef: passed by value
            return value
    if value and all(hasattr(v, "_fields") for v in value):
        return tuple(by_reference(v) for v in value)
    return value


def python_entry(dispatcher):
    """The dispatcher Python calls for kernel ``dispatcher``: its twin with Python wrappers (made on
    first use; the same function under the name ``<qualname>.python``, so that it has its own cache
    entry), or ``dispatcher`` itself if it has its wrappers."""
    if not isinstance(dispatcher, InnerKernel):
        return dispatcher
    twin = dispatcher.__dict__.get("_twin")
    if twin is None:
        f = dispatcher.py_func
        g = types.FunctionType(f.__code__, f.__globals__, f.__name__, f.__defaults__, f.__closure__)
        g.__qualname__ = f.__qualname__ + ".python"
        g.__module__, g.__doc__, g.__kwdefaults__ = f.__module__, f.__doc__, f.__kwdefaults__
        options = {k: v for k, v in dispatcher.targetoptions.items() if k not in WRAPPERS and k != "nopython"}
        twin = dispatcher._twin = njit(cache=OPTIONS["cache"], **options)(g)
        twin.__class__ = SharedCompile  # compiled once across processes (compile_lock.py)
    return twin


def kernel(function=None, **options):
    """``numba.njit(cache=True)`` without reference counting and without Python wrappers (see the
    module doc), with any further njit ``options`` (``fastmath``, ``inline``, ``nogil``). Use as
    ``@kernel`` or ``@kernel(fastmath=True)``."""
    if function is None:
        return lambda f: kernel(f, **options)
    dispatcher = njit(**OPTIONS, **options, **dict.fromkeys(WRAPPERS, True))(function)
    dispatcher.__class__ = InnerKernel  # the same dispatcher; only a call from Python changes
    return dispatcher


@kernel
def copy_into(dst, src):
    """``dst[...] = src`` for C-contiguous arrays of the same size, element by element (numba's
    array assignment may copy ``src`` first, which allocates)."""
    d = dst.reshape(dst.size)
    s = src.reshape(src.size)
    for k in range(s.size):
        d[k] = s[k]
