"""A call's type, resolved once per argument types: numba's resolution of a function's signature for
given argument types, memoised.

numba types a call of an operator or builtin (``a[i, c]``, ``x * y``, ``max``) by trying its typing
templates in order until one accepts the argument types, and types it again when it lowers it.
Each template that declines builds an error report, and an array read tries seven (strings, typed
lists and dicts, ...) before the array's own. A kernel's many array reads and products resolve the
same few hundred (function, argument types) pairs again and again; that search was the largest part
of numba's typing (``benchmarks/results/compile_profile.md``).

:func:`install` wraps ``BaseFunction.get_call_type`` (the method of numba's function types that
does the search) with a memo keyed on the function type (its typing key and templates: a function
augmented with new templates is a new key), the typing context and the argument types: a key seen
before returns a copy of the signature found then. The templates' choice depends only on those
(the argument types carry any literal values), and what a template records when it accepts (its
implementation key on the function type, an overload's compiled implementation) stays recorded,
so a repeated resolution adds nothing a later step needs. Resolutions that fail are not memoised:
they raise as before.
"""

import copy

from numba.core.types import functions

_memo: dict[tuple, object] = {}  # (context, function key, args, kws) -> signature


def _resolve(self, context, args, kws):
    """``BaseFunction.get_call_type``, memoised (module doc)."""
    try:
        # the context itself (hashed by identity and kept alive), not its id: an id of a
        # context collected could come back for a new one
        key = (context, self.key, tuple(args), tuple(sorted(kws.items())))
        hash(key)
    except TypeError:  # an argument type that cannot be hashed: resolved as numba does
        return _numba_get_call_type(self, context, args, kws)
    sig = _memo.get(key)
    if sig is None:
        sig = _memo[key] = _numba_get_call_type(self, context, args, kws)
    return copy.copy(sig)


_numba_get_call_type = functions.BaseFunction.get_call_type


def install():
    """Make the memoised resolution numba's (idempotent)."""
    functions.BaseFunction.get_call_type = _resolve
