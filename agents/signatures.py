"""Which files of a run folder this user's training wrote: an HMAC-SHA256 of each under a key only
this user can read.

A run folder holds pickled Python objects (Stable-Baselines3's ``model.zip`` stores its spaces,
schedules and policy arguments with cloudpickle): loading one runs whatever code it carries, so a
run folder from elsewhere is a program. Training signs the files it writes: ``signatures.json`` in
the run folder maps a file's name to the HMAC-SHA256 of its bytes under the key in
``$XDG_CONFIG_HOME/ballenv/run-key`` (by default ``~/.config/ballenv/run-key``; 32 random bytes
made on first use, readable by this user only; ``BALLENV_RUN_KEY`` names another file). A model is
loaded from a file whose signature is valid, or with ``trust=True`` (``--trust`` on the command
line) for a folder whose source the user trusts; otherwise :func:`require_signed` refuses it
before anything is unpickled.
"""

from __future__ import annotations

import contextlib
import hashlib
import hmac
import json
import os
import pathlib
import stat
import tempfile
from collections.abc import Iterable

from ballenv.files import write_text

SIGNATURES = "signatures.json"
KEY_BYTES = 32


class UntrustedFile(ValueError):
    """A file that would run code when loaded and that this user's training did not write."""


def key_path() -> pathlib.Path:
    """The file of this user's signing key (see the module doc)."""
    given = os.environ.get("BALLENV_RUN_KEY")
    if given:
        return pathlib.Path(given)
    config = os.environ.get("XDG_CONFIG_HOME") or os.path.join(os.path.expanduser("~"), ".config")
    return pathlib.Path(config) / "ballenv" / "run-key"


def key() -> bytes:
    """This user's signing key, made (0600, in a 0700 folder) on first use; ValueError if the file is
    a link, belongs to someone else or others may read it."""
    path = key_path()
    path.parent.mkdir(mode=0o700, parents=True, exist_ok=True)
    if not path.exists():  # made whole, then linked: a process reading it at once sees all of it
        fd, tmp = tempfile.mkstemp(dir=path.parent)  # 0600
        try:
            os.write(fd, os.urandom(KEY_BYTES))
            os.close(fd)
            with contextlib.suppress(FileExistsError):  # another process made it first: use theirs
                os.link(tmp, path)
        finally:
            os.unlink(tmp)
    info = os.lstat(path)
    own = not hasattr(os, "getuid") or info.st_uid == os.getuid()
    if stat.S_ISLNK(info.st_mode) or not own or info.st_mode & 0o077:
        raise ValueError(f"the run signing key {path} must be a file of this user's, readable by no other")
    data = path.read_bytes()
    if len(data) != KEY_BYTES:
        raise ValueError(f"the run signing key {path} holds {len(data)} bytes, expected {KEY_BYTES}")
    return data


def digest(path: pathlib.Path) -> str:
    """HMAC-SHA256 (hex) of the file's bytes under this user's key."""
    mac = hmac.new(key(), digestmod=hashlib.sha256)
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            mac.update(block)
    return mac.hexdigest()


def _table(folder: pathlib.Path) -> dict[str, str]:
    path = folder / SIGNATURES
    try:
        table = json.loads(path.read_text()) if path.exists() else {}
    except (OSError, ValueError):
        return {}
    return {k: v for k, v in table.items() if isinstance(k, str) and isinstance(v, str)}


def sign(paths: Iterable[pathlib.Path]) -> None:
    """Record the signatures of ``paths`` (files of one run folder) in its ``signatures.json``."""
    paths = [pathlib.Path(p) for p in paths]
    if not paths:
        return
    folder = paths[0].parent
    table = _table(folder)
    table.update({p.name: digest(p) for p in paths})
    write_text(folder / SIGNATURES, json.dumps(table, indent=1, sort_keys=True))


def signed(path: pathlib.Path) -> bool:
    """Whether ``path`` carries a valid signature of this user's key."""
    path = pathlib.Path(path)
    expected = _table(path.parent).get(path.name)
    return expected is not None and hmac.compare_digest(expected, digest(path))


def require_signed(path: pathlib.Path, trust: bool) -> None:
    """Raise :class:`UntrustedFile` unless ``path`` was signed by this user's training or ``trust``."""
    if trust or signed(path):
        return
    raise UntrustedFile(
        f"{path} was not written by this user's ballenv training (no valid signature in "
        f"{pathlib.Path(path).parent / SIGNATURES}): loading it would run the Python code it may "
        "carry (a saved model is a pickle). Load it only if you trust its source: pass --trust "
        "(trust=True)"
    )
