"""Saving and loading a :class:`~ballenv.physics.simulate.Trajectory` (``Trajectory.save/load``).

One compressed NumPy archive (``np.savez_compressed``, a ``.npz`` zip of ``.npy`` arrays); the arrays
are stored exactly (float64, no resampling), so a load returns what was saved bit for bit.

==================  ==================  ========  ===================================================
key                 shape               dtype     content
==================  ==================  ========  ===================================================
``format``          ()                  str       ``"ballenv.trajectory"``
``version``         ()                  int64     layout version, 1
``t``               (T,)                float64   time (s)
``x``               (T, R, N, 2)        float64   node positions (m)
``v``               (T, R, N, 2)        float64   node velocities (m/s)
``pressure``        (T, R)              float64   gauge pressure (Pa), 0 for rings without gas
``contact_force``   (T, R, N, 2)        float64   ground reaction per node (N), friction included
``event_table``     (E, 4)              float64   t (s), ring, kind (0 touchdown, 1 lift-off,
                                                  2 apex), centre-of-mass height (m)
``scene``           ()                  str       the :class:`Scene` as JSON: its fields, with
                                                  ``rings``, ``grounds``, ``drums`` lists of field dicts
``stats``           ()                  str       the :class:`SimulationStats` as JSON
==================  ==================  ========  ===================================================

(T records, R rings, N nodes per ring, E events.) ``np.load(path)`` reads it without ballenv;
``json.loads(str(archive["scene"]))`` gives the scene's parameters in SI units. ``Trajectory.events``
is rebuilt from ``event_table``. No pickled objects are stored (``allow_pickle=False`` on load).
"""

from __future__ import annotations

import dataclasses
import json
import os
import pathlib
import zipfile
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from .events import EVENT_KINDS, event_list
from .scene import Drum, Ground, Ring, Scene

if TYPE_CHECKING:
    from .simulation import Trajectory

FORMAT = "ballenv.trajectory"
VERSION = 1
ARRAYS = ("t", "x", "v", "pressure", "contact_force", "event_table")


def scene_to_dict(scene: Scene) -> dict[str, Any]:
    """``scene`` as a JSON-ready dict (rings, grounds and drums as lists of field dicts)."""
    out = {}
    for f in dataclasses.fields(scene):
        value = getattr(scene, f.name)
        if f.name in ("rings", "grounds", "drums"):
            value = [dataclasses.asdict(item) for item in value]
        elif isinstance(value, tuple):
            value = list(value)
        out[f.name] = value
    return out


def scene_from_dict(data: Mapping[str, Any]) -> Scene:
    """The :class:`Scene` of a dict made by :func:`scene_to_dict` (values validated again)."""
    data = dict(data)
    rings = [Ring(**_tupled(r)) for r in data.pop("rings")]
    grounds = [Ground(**g) for g in data.pop("grounds")]
    drums = [Drum(**d) for d in data.pop("drums", [])]
    if isinstance(data.get("gravity"), list):
        data["gravity"] = tuple(data["gravity"])
    return Scene(rings=rings, grounds=grounds, drums=drums, **data)


def _tupled(ring: Mapping[str, Any]) -> dict[str, Any]:
    return {k: tuple(v) if isinstance(v, list) else v for k, v in ring.items()}


def save(traj: Trajectory, path: str | os.PathLike[str]) -> pathlib.Path:
    """Write ``traj`` to ``path`` (``.npz`` is appended by NumPy if missing); returns the path."""
    path = pathlib.Path(path)
    if path.suffix != ".npz":
        path = path.with_name(path.name + ".npz")
    table = traj.event_table if traj.event_table is not None else np.zeros((0, 4))
    stats = dataclasses.asdict(traj.stats)
    stats["effects"] = list(stats["effects"])
    np.savez_compressed(
        path,
        format=np.array(FORMAT),
        version=np.array(VERSION, dtype=np.int64),
        t=np.asarray(traj.t, dtype=float),
        x=np.asarray(traj.x, dtype=float),
        v=np.asarray(traj.v, dtype=float),
        pressure=np.asarray(traj.pressure, dtype=float),
        contact_force=np.asarray(traj.contact_force, dtype=float),
        event_table=np.asarray(table, dtype=float).reshape(-1, 4),
        scene=np.array(json.dumps(scene_to_dict(traj.scene))),
        stats=np.array(json.dumps(stats)),
    )
    return path


def load(path: str | os.PathLike[str]) -> Trajectory:
    """Read a trajectory written by :func:`save`; a missing or foreign file raises ValueError
    (FileNotFoundError if it does not exist)."""
    from .simulation import SimulationStats, Trajectory

    path = pathlib.Path(path)
    if not path.exists():
        raise FileNotFoundError(f"Trajectory.load: no such file: {path}")
    if not zipfile.is_zipfile(path):
        raise ValueError(f"Trajectory.load: {path} is not a .npz archive (not a zip file)")
    try:
        archive = np.load(path, allow_pickle=False)
    except (OSError, ValueError, zipfile.BadZipFile) as err:
        raise ValueError(f"Trajectory.load: {path} is not a .npz archive ({err})") from err
    with archive:
        keys = set(archive.files)
        if "format" not in keys or str(archive["format"]) != FORMAT:
            raise ValueError(
                f"Trajectory.load: {path} is not a ballenv trajectory (no format = {FORMAT!r}; "
                f"keys: {sorted(keys)})"
            )
        version = int(archive["version"]) if "version" in keys else None
        if version != VERSION:
            raise ValueError(
                f"Trajectory.load: {path} has layout version {version}, this ballenv reads {VERSION}"
            )
        missing = [k for k in (*ARRAYS, "scene", "stats") if k not in keys]
        if missing:
            raise ValueError(f"Trajectory.load: {path} lacks {', '.join(missing)}")
        arrays = {k: archive[k] for k in ARRAYS}
        try:
            scene = scene_from_dict(json.loads(str(archive["scene"])))
            stats = json.loads(str(archive["stats"]))
        except (ValueError, TypeError, KeyError) as err:
            raise ValueError(f"Trajectory.load: {path} has an invalid scene or stats record ({err})") from err
    t, x = arrays["t"], arrays["x"]
    n_rings, n_nodes = len(scene.rings), scene.rings[0].n_nodes
    shapes = {
        "x": (len(t), n_rings, n_nodes, 2),
        "v": (len(t), n_rings, n_nodes, 2),
        "pressure": (len(t), n_rings),
        "contact_force": (len(t), n_rings, n_nodes, 2),
    }
    for key, shape in shapes.items():
        if arrays[key].shape != shape:
            raise ValueError(
                f"Trajectory.load: {path}: {key} has shape {arrays[key].shape}, expected {shape}"
            )
    table = arrays["event_table"]
    if (
        table.ndim != 2
        or table.shape[1] != 4
        or np.any((table[:, 2] < 0) | (table[:, 2] >= len(EVENT_KINDS)))
    ):
        raise ValueError(f"Trajectory.load: {path}: event_table must be (E, 4) rows with known event kinds")
    stats["effects"] = tuple(stats["effects"])
    return Trajectory(
        t=t,
        x=x,
        v=arrays["v"],
        pressure=arrays["pressure"],
        contact_force=arrays["contact_force"],
        events=event_list(table),
        stats=SimulationStats(**stats),
        scene=scene,
        event_table=table,
    )
