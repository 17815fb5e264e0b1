"""Saving and loading a 3-D ball's trajectory (:class:`ballenv.shell.simulation.Trajectory`).

A saved trajectory is one compressed NumPy archive (``np.savez_compressed``, a ``.npz`` zip of
``.npy`` arrays), written atomically (:func:`ballenv.files.atomic_path`); the arrays are stored
exactly (float64), so a load returns what was saved bit for bit.

==================  ==================  ========  ===================================================
key                 shape               dtype     content
==================  ==================  ========  ===================================================
``format``          ()                  str       ``"ballenv.shell_trajectory"``
``version``         ()                  int64     layout version, 1
``t``               (T,)                float64   time (s)
``x``               (T, S, V, 3)        float64   vertex positions (m)
``v``               (T, S, V, 3)        float64   vertex velocities (m/s)
``contact_force``   (T, S, V, 3)        float64   contact force per vertex (N), friction included
``pressure``        (T, S)              float64   gauge pressure (Pa)
``boundary_work``   (T, S) or (0, 0)    float64   work (J) credited for moving grounds
``event_table``     (E, 4)              float64   t (s), shell, kind (0 touchdown, 1 lift-off,
                                                  2 apex), centre-of-mass height (m)
``scene``           ()                  str       the :class:`ballenv.shell.Scene` as JSON: its
                                                  fields, ``shells``, ``grounds`` and ``drums`` as
                                                  lists of field dicts
``stats``           ()                  str       the ``SimulationStats`` as JSON
==================  ==================  ========  ===================================================

(T records, S shells, V vertices per shell, E events.) The loader trusts nothing in the file: no
pickles (``allow_pickle=False``), every array's dtype and shape checked against the scene before
it is decompressed, their total bounded, and the scene rebuilt through its validating
constructors; anything wrong is one ``ValueError`` naming the file.
"""

from __future__ import annotations

import dataclasses
import json
import os
import pathlib
import struct
import zipfile
import zlib
from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .files import atomic_path, npz_headers, npz_member
from .shell.scene import Drum, Ground, Scene, Shell
from .shell.simulation import SimulationStats, Trajectory

FORMAT = "ballenv.shell_trajectory"
VERSION = 1
EVENT_KINDS = ("touchdown", "liftoff", "apex")
ARRAYS = ("t", "x", "v", "contact_force", "pressure", "boundary_work", "event_table")
MAX_LOAD_BYTES = 2**31  # default cap on the arrays a file may declare, decompressed (2 GiB)
MAX_RECORD_CHARS = 2**20  # cap on the scene's and the statistics' JSON (characters)
F64 = NDArray[np.float64]

# what may go wrong inside a file that is not ours (every one becomes the loader's ValueError)
UNREADABLE = (
    OSError, EOFError, zipfile.BadZipFile, zlib.error, KeyError, TypeError, IndexError,
    RecursionError, UnicodeDecodeError, OverflowError, struct.error, AttributeError,
    NotImplementedError,  # zipfile: a member's compression method it does not know
    RuntimeError,  # zipfile: a member flagged as encrypted
)  # fmt: skip


def scene_to_dict(scene: Scene) -> dict[str, Any]:
    """``scene`` as a JSON-ready dict (shells, grounds and drums as lists of field dicts)."""
    out: dict[str, Any] = {}
    for f in dataclasses.fields(scene):
        value = getattr(scene, f.name)
        if f.name in ("shells", "grounds", "drums"):
            value = [dataclasses.asdict(item) for item in value]
        elif isinstance(value, tuple):
            value = list(value)
        out[f.name] = value
    return out


def _tupled(fields: Mapping[str, Any]) -> dict[str, Any]:
    return {k: tuple(v) if isinstance(v, list) else v for k, v in fields.items()}


def scene_from_dict(data: Mapping[str, Any]) -> Scene:
    """The :class:`Scene` of a dict made by :func:`scene_to_dict`, every value validated again by
    the constructors of ``Shell``, ``Ground``, ``Drum`` and ``Scene``."""
    data = dict(data)
    shells = [Shell(**_tupled(s)) for s in data.pop("shells")]
    grounds = [Ground(**_tupled(g)) for g in data.pop("grounds")]
    drums = [Drum(**_tupled(d)) for d in data.pop("drums", [])]
    if isinstance(data.get("gravity"), list):
        data["gravity"] = tuple(data["gravity"])
    return Scene(shells=shells, grounds=grounds, drums=drums, **data)


def event_table(events: list[tuple[float, int, str, float]]) -> F64:
    """(E, 4) rows ``t s, shell, kind code, height m`` of ``events`` (codes: :data:`EVENT_KINDS`)."""
    rows = [(t, k, EVENT_KINDS.index(kind), z) for t, k, kind, z in events]
    return np.array(rows, dtype=np.float64).reshape(-1, 4)


def save(traj: Trajectory, path: str | os.PathLike[str]) -> pathlib.Path:
    """Write ``traj`` to ``path`` (``.npz`` appended if missing), atomically: the file appears whole
    or not at all; returns the path."""
    path = pathlib.Path(path)
    if path.suffix != ".npz":
        path = path.with_name(path.name + ".npz")
    with atomic_path(path) as tmp:  # a kill while writing leaves an existing file as it was
        np.savez_compressed(
            tmp,
            format=np.array(FORMAT),
            version=np.array(VERSION, dtype=np.int64),
            t=np.asarray(traj.t, dtype=np.float64),
            x=np.asarray(traj.x, dtype=np.float64),
            v=np.asarray(traj.v, dtype=np.float64),
            contact_force=np.asarray(traj.contact_force, dtype=np.float64),
            pressure=np.asarray(traj.pressure, dtype=np.float64),
            boundary_work=np.asarray(traj.boundary_work, dtype=np.float64),
            event_table=event_table(traj.events),
            scene=np.array(json.dumps(scene_to_dict(traj.scene))),
            stats=np.array(json.dumps(dataclasses.asdict(traj.stats))),
        )
    return path


def load(path: str | os.PathLike[str], max_bytes: int = MAX_LOAD_BYTES) -> Trajectory:
    """A trajectory written by :func:`save`, exactly as it was. Anything wrong with the file, or
    arrays declaring more than ``max_bytes`` (bytes, decompressed), raises one ValueError naming the
    file (FileNotFoundError if it does not exist)."""
    path = pathlib.Path(path)
    if not path.exists():
        raise FileNotFoundError(f"shell_files.load: no such file: {path}")
    if not zipfile.is_zipfile(path):
        raise ValueError(f"shell_files.load: {path} is not a .npz archive (not a zip file)")
    try:
        return _load(path, max_bytes)
    except ValueError as err:
        if str(err).startswith("shell_files.load:"):
            raise
        raise ValueError(f"shell_files.load: {path} is not a readable shell trajectory ({err})") from err
    except UNREADABLE as err:
        message = f"{type(err).__name__}: {err}"
        raise ValueError(f"shell_files.load: {path} is not a readable shell trajectory ({message})") from err


def _load(path: pathlib.Path, max_bytes: int) -> Trajectory:
    with zipfile.ZipFile(path) as archive:
        headers = npz_headers(path, archive, "shell_files.load")
        _check_records(path, archive, headers)
        scene, stats = _records(path, archive)
        _check_arrays(path, headers, scene, max_bytes)
        arrays = {k: npz_member(archive, k) for k in ARRAYS}
    table = arrays.pop("event_table")
    kinds, shells = table[:, 2], table[:, 1]
    bad_kind = ~np.isin(kinds, np.arange(len(EVENT_KINDS)))
    if np.any(bad_kind) or np.any(~np.isin(shells, np.arange(len(scene.shells)))):
        raise ValueError(f"shell_files.load: {path}: event_table rows name unknown event kinds or shells")
    events = [(float(t), int(k), EVENT_KINDS[int(c)], float(z)) for t, k, c, z in table]
    return Trajectory(events=events, stats=stats, scene=scene, **arrays)


def _check_records(path: pathlib.Path, archive: zipfile.ZipFile, headers: dict[str, Any]) -> None:
    """The format, version, scene and statistics records: present, scalar, of their types, bounded."""
    missing = [k for k in ("format", "version", *ARRAYS, "scene", "stats") if k not in headers]
    if "format" in missing:
        raise ValueError(f"shell_files.load: {path} is not a shell trajectory (no format = {FORMAT!r})")
    for key in ("format", "scene", "stats"):
        if key in headers and (headers[key][0] != () or headers[key][1].kind != "U"):
            raise ValueError(f"shell_files.load: {path}: {key} must be a string, not {headers[key]}")
        if key in headers and headers[key][1].itemsize // 4 > MAX_RECORD_CHARS:
            raise ValueError(f"shell_files.load: {path}: {key} is longer than {MAX_RECORD_CHARS} characters")
    if str(npz_member(archive, "format")) != FORMAT:
        raise ValueError(f"shell_files.load: {path} is not a shell trajectory (format is not {FORMAT!r})")
    if "version" in missing or headers["version"] != ((), np.dtype(np.int64)):
        raise ValueError(
            f"shell_files.load: {path} has no int64 layout version, this ballenv reads {VERSION}"
        )
    version = int(npz_member(archive, "version"))
    if version != VERSION:
        raise ValueError(
            f"shell_files.load: {path} has layout version {version}, this ballenv reads {VERSION}"
        )
    if missing:
        raise ValueError(f"shell_files.load: {path} lacks {', '.join(missing)}")


def _records(path: pathlib.Path, archive: zipfile.ZipFile) -> tuple[Scene, SimulationStats]:
    """The scene (validated by its constructors) and the statistics."""
    try:
        scene = scene_from_dict(json.loads(str(npz_member(archive, "scene"))))
        fields = json.loads(str(npz_member(archive, "stats")))
        if not isinstance(fields, dict) or set(fields) != {
            f.name for f in dataclasses.fields(SimulationStats)
        }:
            raise ValueError("the statistics' fields are not SimulationStats'")
        if not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in fields.values()):
            raise ValueError("the statistics must be numbers")
        stats = SimulationStats(**fields)
    except (ValueError, TypeError, KeyError, AttributeError, RecursionError) as err:
        raise ValueError(f"shell_files.load: {path} has an invalid scene or stats record ({err})") from err
    return scene, stats


def _check_arrays(path: pathlib.Path, headers: dict[str, Any], scene: Scene, max_bytes: int) -> None:
    """Every array float64 and of the shape the scene and the record count give, and all of them
    together within ``max_bytes`` (decompressed), before any is read."""
    n = headers["t"][0][0] if len(headers["t"][0]) == 1 else -1
    s, v = len(scene.shells), scene.shells[0].n_vertices
    work = headers["boundary_work"][0]
    shapes = {
        "t": (n,),
        "x": (n, s, v, 3),
        "v": (n, s, v, 3),
        "contact_force": (n, s, v, 3),
        "pressure": (n, s),
        "boundary_work": (0, 0) if work == (0, 0) else (n, s),
        "event_table": (headers["event_table"][0][0] if headers["event_table"][0] else -1, 4),
    }
    total = 0
    for key, shape in shapes.items():
        got, dtype = headers[key]
        if got != shape or -1 in shape:
            raise ValueError(f"shell_files.load: {path}: {key} has shape {got}, expected {shape}")
        if dtype != np.dtype(np.float64):
            raise ValueError(f"shell_files.load: {path}: {key} has dtype {dtype}, expected float64")
        total += int(np.prod(shape)) * 8
    if total > max_bytes:
        raise ValueError(
            f"shell_files.load: {path} declares {total} bytes of arrays, more than max_bytes = {max_bytes}"
        )
