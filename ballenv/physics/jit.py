"""How the simulator's kernels are compiled: :func:`kernel`, numba's ``njit`` with the on-disk cache
and without reference counting.

numba counts references to every array a compiled function holds: each call of a function that
takes a record of arrays (``Model``, ``State``, ``Workspace``: about 60 arrays) adds one and removes
one per array, each an atomic memory operation. In the env's control step these counts were 13 %
of the whole process's time, and with threads stepping different envs they contend for the same
cache lines (every thread holds the same model arrays). The kernels allocate nothing: every array
they touch is owned by the Python object that calls them (a ``Simulation``, an env's batch) for the
whole call, so the counts protect nothing. Compiled without them (numba's ``_nrt=False``), a kernel
that tries to allocate (``np.empty``, a copying array expression, returning a new array) does not
compile: "NRT required but not enabled" names it.
"""

from numba import njit

OPTIONS = {"cache": True, "_nrt": False}


def kernel(function=None, **options):
    """``numba.njit(cache=True)`` without reference counting, with any further njit ``options``
    (``fastmath``, ``inline``, ``nogil``). Use as ``@kernel`` or ``@kernel(fastmath=True)``."""
    if function is None:
        return njit(**OPTIONS, **options)
    return njit(**OPTIONS, **options)(function)


@kernel
def copy_into(dst, src):
    """``dst[...] = src`` for C-contiguous arrays of the same size, element by element (numba's
    array assignment may copy ``src`` first, which allocates)."""
    d = dst.reshape(dst.size)
    s = src.reshape(src.size)
    for k in range(s.size):
        d[k] = s[k]
