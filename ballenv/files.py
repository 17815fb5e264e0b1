"""Writing files so that no reader ever sees half of one.

Every file the project writes (trajectories, replay pages, run folders' records, results pages)
is written to a temporary file in the target's folder, flushed to disk, and then renamed over the
target (``os.replace``: atomic on POSIX and Windows). A process killed while writing leaves the
old file as it was (and at most a ``.NAME.*.tmp`` file beside it, which it removes itself when it
fails with an exception).
"""

from __future__ import annotations

import contextlib
import os
import pathlib
import tempfile
import zipfile
from collections.abc import Iterator
from typing import Any

import numpy as np
from numpy.typing import NDArray


def _default_mode() -> int:
    """The permissions a new file gets under this process's umask (``0o666 & ~umask``)."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


MODE = _default_mode()


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[pathlib.Path]:
    """A temporary path beside ``path`` to write into (it ends like ``path``, so writers that add
    a suffix add none); when the block ends without an exception the file there replaces ``path``
    at once, else it is removed and ``path`` is left as it was."""
    path = pathlib.Path(path)
    fd, name = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp" + path.suffix)
    os.close(fd)
    tmp = pathlib.Path(name)
    try:
        yield tmp
        with open(tmp, "rb+") as f:
            os.fsync(f.fileno())
        os.chmod(tmp, MODE)
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def write_text(path: str | os.PathLike[str], text: str, encoding: str = "utf-8") -> pathlib.Path:
    """Write ``text`` to ``path`` atomically (:func:`atomic_path`); returns the path."""
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding=encoding)
    return pathlib.Path(path)


def write_bytes(path: str | os.PathLike[str], data: bytes) -> pathlib.Path:
    """Write ``data`` to ``path`` atomically (:func:`atomic_path`); returns the path."""
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)
    return pathlib.Path(path)


def npz_headers(
    path: pathlib.Path, archive: zipfile.ZipFile, owner: str
) -> dict[str, tuple[tuple[int, ...], np.dtype[Any]]]:
    """Shape and dtype of each ``.npy`` member of the ``.npz`` ``archive`` at ``path``, read from its
    header (a few bytes decompressed) before any array is; ``ValueError`` naming ``owner`` (the
    loader) for a member that is not a ``.npy`` array of format version 1.0 or 2.0."""
    out = {}
    for name in archive.namelist():
        if not name.endswith(".npy"):
            raise ValueError(f"{owner}: {path} holds {name!r}, not a .npy array")
        with archive.open(name) as member:
            version = np.lib.format.read_magic(member)
            if version not in ((1, 0), (2, 0)):
                raise ValueError(f"{owner}: {path}: {name} has .npy version {version}")
            read = (
                np.lib.format.read_array_header_1_0
                if version == (1, 0)
                else np.lib.format.read_array_header_2_0
            )
            shape, _, dtype = read(member)
        out[name[: -len(".npy")]] = (tuple(int(n) for n in shape), dtype)
    return out


def npz_member(archive: zipfile.ZipFile, key: str) -> NDArray[Any]:
    """The array ``key`` of the ``.npz`` ``archive`` (its header already checked), without pickles."""
    with archive.open(key + ".npy") as member:
        return np.lib.format.read_array(member, allow_pickle=False)
