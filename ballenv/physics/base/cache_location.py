"""Where numba keeps the simulator's compiled kernels.

numba caches a kernel beside its source (``__pycache__``) when the package folder is writable. In a
read-only install it would fall back to its own user-wide folder, or fail with "no locator
available" where that is not writable either. So, unless ``NUMBA_CACHE_DIR`` is set (which always
wins), the cache goes to the first writable of: the package folder; ``$XDG_CACHE_HOME/ballenv/numba``
(by default ``~/.cache/ballenv/numba``, made 0700); none, and then every run compiles. A location
other than the package folder is said once (:func:`.compile_notice.log_info`). A read-only install
can ship a populated cache: build it once with ``NUMBA_CACHE_DIR`` pointing into the install and
set the same ``NUMBA_CACHE_DIR`` when running it.
"""

import os
import pathlib
import tempfile
from collections.abc import Callable

from numba.core import config

from .compile_lock import private_dir
from .compile_notice import log_info

PACKAGE = pathlib.Path(__file__).resolve().parent.parent  # ballenv/physics: the kernels' sources
MOVED = "the package folder %s is read-only: numba's cache of the simulator goes to %s"
NONE = "no writable folder for numba's cache (the package folder %s is read-only): every run compiles"


def writable(folder: pathlib.Path) -> bool:
    """Whether a file can be made in ``folder`` (as numba checks it)."""
    try:
        with tempfile.TemporaryFile(dir=folder):
            return True
    except OSError:
        return False


def user_folder() -> pathlib.Path:
    cache = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return pathlib.Path(cache) / "ballenv" / "numba"


def choose(
    package: pathlib.Path = PACKAGE, is_writable: Callable[[pathlib.Path], bool] = writable
) -> tuple[bool, str]:
    """``(cache, folder)``: whether to cache, and where (``""``: beside the sources, numba's default)."""
    given = config.CACHE_DIR  # type: ignore[attr-defined]  # (numba sets its settings at import)
    if given or is_writable(package):
        return True, given or ""
    folder = user_folder()
    if private_dir(str(folder)) and is_writable(folder):
        log_info(MOVED, package, folder)
        return True, str(folder)
    log_info(NONE, package)
    return False, ""


def apply() -> bool:
    """Point numba's cache where :func:`choose` says; returns whether kernels are cached."""
    cache, folder = choose()
    if folder:
        config.CACHE_DIR = folder  # type: ignore[attr-defined]
    return cache
