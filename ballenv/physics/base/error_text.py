"""numba's error messages as plain text, without the terminal markup it starts colorama for.

numba marks up the text of every error it makes, and most are made and caught while it compiles: a
typing template that declines, a value with no literal type, an implementation looked up in the
wrong registry. Each markup starts and stops colorama's stream wrapper, tens of thousands of times
in a first compile. With numba's default colour scheme (``"no_color"``) the markup is only the bold
weight, so :func:`install` makes numba's one colour scheme return the text as it is. A scheme chosen
with ``NUMBA_COLOR_SCHEME`` is left alone, and without colorama numba marks nothing up anyway.
"""

from numba.core import config, errors


def _plain(msg, color=None, style=None):
    """The message as it is (numba's ``_markup`` without colorama)."""
    return msg


def install():
    """Plain error text under numba's default colour scheme (idempotent)."""
    scheme = errors.termcolor()  # the instance numba's errors and typeof share
    if config.COLOR_SCHEME == "no_color" and hasattr(scheme, "_markup"):
        scheme._markup = _plain
