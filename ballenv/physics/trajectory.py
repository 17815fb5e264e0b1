"""What a simulation recorded: :class:`Trajectory` (states, events, statistics),
:class:`SimulationStats`, the energy of recorded states (:func:`energy`), saving and loading.

A saved trajectory (``Trajectory.save/load``) is one compressed NumPy archive
(``np.savez_compressed``, a ``.npz`` zip of ``.npy`` arrays); the arrays are stored exactly
(float64, no resampling), so a load returns what was saved bit for bit.

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
import struct
import zipfile
import zlib
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..files import atomic_path, npz_headers, npz_member
from .base.layout import EVENT_APEX, EVENT_HEIGHT, EVENT_KIND, EVENT_RING, EVENT_T
from .build import build_barrier_workspace, build_model, build_ring_contact_workspace
from .effects.assembly import ENERGY_PARTS, ring_energy
from .model import Model
from .scene import Drum, Ground, Ring, Scene
from .step.energy_budget import self_contact_energy
from .step.events import EVENT_KINDS, event_list
from .walls.ring_barrier import contact_energy_by_ring, pairs_per_node

FORMAT = "ballenv.trajectory"
VERSION = 1
ARRAYS = ("t", "x", "v", "pressure", "contact_force", "event_table")
MAX_LOAD_BYTES = 2**31  # default cap on the arrays a file may declare, decompressed (2 GiB)
MAX_RECORD_CHARS = 2**20  # cap on the scene's and the statistics' JSON (characters)


@dataclass(frozen=True)
class SimulationStats:
    """Cost of a run: accepted and rejected steps, Newton iterations (linear solves), wall time (s);
    ``rejections`` counts the rejected steps by reason ("newton", "energy", "intrusion",
    "self_intersection", "impulse": the adaptive step's contact impulse above its bound, "error": the
    local error above ``Scene.rtol``, ``atol``);
    ``energy_projected``: accepted (step, ring) pairs whose energy rose above the ring's budget (its
    start energy plus the work of actuation and collisions) by a small step error, removed from the
    ring's velocities relative to its centre of mass; ``energy_removed`` (J): the sum of those
    excesses (``step.energy_budget.within_energy_budget``); ``collision_gain`` (J): the energy ring-ring and
    self-contact impulses created by pushing out nodes that started a step inside the contact
    distance, summed over the steps where their net effect was a gain (a source of energy besides
    actuation); ``boundary_work`` (J): the work moving grounds did on the rings,
    ``sum_steps h sum_i f_i . w`` (``step.energy_budget.boundary_work``; 0 with fixed grounds), which their
    energy budgets are credited with; ``newton_rescues``: steps taken by Newton's rescue after a
    stop at ``dt_min`` (``Scene.newton_rescue_max_iter``)."""

    steps: int
    rejected_steps: int
    newton_iterations: int
    wall_time: float
    effects: tuple[str, ...]
    integrator: str
    rejections: dict[str, int] = field(default_factory=dict)  # rejected steps by reason (layout.REJECTIONS)
    energy_projected: int = 0
    energy_removed: float = 0.0
    collision_gain: float = 0.0
    boundary_work: float = 0.0
    newton_rescues: int = 0


@dataclass
class Trajectory:
    """Recorded states of a simulation (SI units).

    Attributes:
        t: (T,) time (s).
        x: (T, n_rings, n_nodes, 2) node positions (m).
        v: (T, n_rings, n_nodes, 2) node velocities (m/s).
        pressure: (T, n_rings) gauge pressure (Pa); 0 for rings without gas.
        contact_force: (T, n_rings, n_nodes, 2) ground reaction (N); zero without grounds.
        events: list of (t, ring, kind) with kind in {"touchdown", "liftoff", "apex"}.
        stats: :class:`SimulationStats`.
        scene: the simulated :class:`Scene`.
    """

    t: NDArray[np.float64]
    x: NDArray[np.float64]
    v: NDArray[np.float64]
    pressure: NDArray[np.float64]
    contact_force: NDArray[np.float64]
    events: list[tuple[float, int, str]]
    stats: SimulationStats
    scene: Scene = field(repr=False)
    event_table: NDArray[np.float64] | None = field(default=None, repr=False)

    def apexes(self, ring: int = 0) -> NDArray[np.float64]:
        """(k, 2) array of (t (s), centre-of-mass height (m)) at the apexes of ``ring``,
        interpolated inside the step (cubic Hermite), not sampled."""
        rows = self.event_table
        if rows is None or len(rows) == 0:
            return np.zeros((0, 2))
        sel = (rows[:, EVENT_RING] == ring) & (rows[:, EVENT_KIND] == EVENT_APEX)
        return rows[sel][:, [EVENT_T, EVENT_HEIGHT]]

    def centre_of_mass(self) -> NDArray[np.float64]:
        """(T, n_rings, 2) centre of mass (m); nodes of a ring have equal mass."""
        return self.x.mean(axis=2)

    def energy(self) -> dict[str, NDArray[np.float64]]:
        """Energy (J) per record and ring: dict of (T, n_rings) arrays.

        Keys: kinetic, stretching, bending, gas (the gas-law potential), gravity, with the self-contact
        barrier (``Scene.self_intersection = "barrier"``) self_contact, with rings colliding through
        it ring_contact (each node-edge pair's barrier energy, half to either ring), and total. Computed with
        the scene's gas amounts and the registry's effects: records after a
        :meth:`Simulation.set_rest_pressure` hold another amount of gas than this counts.
        """
        return energy(self.scene, self.x, self.v)

    def save(self, path: str | os.PathLike[str]) -> pathlib.Path:
        """Write this trajectory to ``path`` (a compressed ``.npz``; layout in
        :mod:`ballenv.physics.trajectory`); returns the path written."""
        return save(self, path)

    @classmethod
    def load(cls, path: str | os.PathLike[str], max_bytes: int = MAX_LOAD_BYTES) -> Trajectory:
        """A trajectory saved by :meth:`save`, exactly as it was. The file is trusted for nothing:
        anything wrong with it, or arrays declaring more than ``max_bytes`` (bytes, decompressed;
        default 2 GiB), is one ValueError naming the file (:func:`load`)."""
        return load(path, max_bytes)


def energy(scene: Scene, x: ArrayLike, v: ArrayLike) -> dict[str, NDArray[np.float64]]:
    """Mechanical plus gas energy (J) of states ``x, v`` (..., n_rings, n_nodes, 2); see Trajectory."""
    model = build_model(scene)
    x = np.asarray(x, dtype=float)
    v = np.asarray(v, dtype=float)
    lead = x.shape[:-2]
    xs = np.ascontiguousarray(x.reshape(-1, x.shape[-2], 2))
    vs = np.ascontiguousarray(v.reshape(-1, x.shape[-2], 2))
    n_rings = len(scene.rings)
    names = ENERGY_PARTS + (("self_contact",) if model.self_barrier else ())
    table = np.zeros((xs.shape[0], len(names)))
    bw = build_barrier_workspace(xs.shape[1]) if model.self_barrier else None
    for k in range(xs.shape[0]):
        ring_energy(model, k % n_rings, xs[k], vs[k], table[k])
        if bw is not None:
            table[k, -1] = self_contact_energy(model, k % n_rings, xs[k], bw)
    out = {name: table[:, j].reshape(lead) for j, name in enumerate(names)}
    total = table.sum(axis=1).reshape(lead)
    if model.ring_barrier:
        between = _contact_energy_by_ring(model, xs.reshape(-1, n_rings, xs.shape[1], 2)).reshape(lead)
        out["ring_contact"] = between
        total = total + between
    out["total"] = total
    return out


def _contact_energy_by_ring(model: Model, states: NDArray[np.float64]) -> NDArray[np.float64]:
    """(T, R): the barrier energy (J) between rings of each state (T, R, N, 2), each pair's half to
    either ring."""
    rw = build_ring_contact_workspace(states.shape[1], states.shape[2], pairs_per_node(model))
    out = np.zeros(states.shape[:2])
    for k, x in enumerate(states):
        x = np.ascontiguousarray(x)
        contact_energy_by_ring(model, x, rw, out[k])
    return out


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
    """Write ``traj`` to ``path`` (``.npz`` appended if missing), atomically: the file appears whole
    or not at all (:func:`ballenv.files.atomic_path`); returns the path."""
    path = pathlib.Path(path)
    if path.suffix != ".npz":
        path = path.with_name(path.name + ".npz")
    table = traj.event_table if traj.event_table is not None else np.zeros((0, 4))
    stats = dataclasses.asdict(traj.stats)
    stats["effects"] = list(stats["effects"])
    with atomic_path(path) as tmp:  # a kill while writing leaves an existing file as it was
        _write_archive(tmp, traj, table, stats)
    return path


def _write_archive(
    path: pathlib.Path, traj: Trajectory, table: NDArray[np.float64], stats: dict[str, Any]
) -> None:
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


# what may go wrong inside a file that is not ours (every one becomes the loader's ValueError)
UNREADABLE = (
    OSError, EOFError, zipfile.BadZipFile, zlib.error, KeyError, TypeError, IndexError,
    RecursionError, UnicodeDecodeError, OverflowError, struct.error,
    NotImplementedError,  # zipfile: a member's compression method it does not know
    RuntimeError,  # zipfile: a member flagged as encrypted
)  # fmt: skip


def load(path: str | os.PathLike[str], max_bytes: int = MAX_LOAD_BYTES) -> Trajectory:
    """Read a trajectory written by :func:`save`. The file is trusted for nothing: every array's
    declared dtype and shape are checked against the scene before anything is decompressed, the
    arrays together may not declare more than ``max_bytes`` (bytes, decompressed), and anything
    wrong with it raises one ValueError naming the file (FileNotFoundError if it does not exist)."""
    path = pathlib.Path(path)
    if not path.exists():
        raise FileNotFoundError(f"Trajectory.load: no such file: {path}")
    if not zipfile.is_zipfile(path):
        raise ValueError(f"Trajectory.load: {path} is not a .npz archive (not a zip file)")
    try:
        return _load(path, max_bytes)
    except ValueError as err:
        if str(err).startswith("Trajectory.load:"):
            raise
        raise ValueError(f"Trajectory.load: {path} is not a readable ballenv trajectory ({err})") from err
    except UNREADABLE as err:
        message = f"{type(err).__name__}: {err}"
        raise ValueError(f"Trajectory.load: {path} is not a readable ballenv trajectory ({message})") from err


def _load(path: pathlib.Path, max_bytes: int) -> Trajectory:
    with zipfile.ZipFile(path) as archive:
        headers = npz_headers(path, archive, "Trajectory.load")
        _check_records(path, archive, headers)
        scene, stats = _records(path, archive)
        _check_arrays(path, headers, scene, max_bytes)
        arrays = {k: npz_member(archive, k) for k in ARRAYS}
    table = arrays["event_table"]
    kinds, rings = table[:, 2], table[:, 1]
    if np.any((kinds < 0) | (kinds >= len(EVENT_KINDS))) or np.any((rings < 0) | (rings >= len(scene.rings))):
        raise ValueError(f"Trajectory.load: {path}: event_table rows name unknown event kinds or rings")
    stats["effects"] = tuple(stats["effects"])
    return Trajectory(
        t=arrays["t"],
        x=arrays["x"],
        v=arrays["v"],
        pressure=arrays["pressure"],
        contact_force=arrays["contact_force"],
        events=event_list(table),
        stats=SimulationStats(**stats),
        scene=scene,
        event_table=table,
    )


def _check_records(path: pathlib.Path, archive: zipfile.ZipFile, headers: dict[str, Any]) -> None:
    """The format, version, scene and statistics records: present, scalar, of their types, bounded."""
    missing = [k for k in ("format", "version", *ARRAYS, "scene", "stats") if k not in headers]
    if "format" in missing:
        raise ValueError(f"Trajectory.load: {path} is not a ballenv trajectory (no format = {FORMAT!r})")
    for key in ("format", "scene", "stats"):
        if key in headers and (headers[key][0] != () or headers[key][1].kind != "U"):
            raise ValueError(f"Trajectory.load: {path}: {key} must be a string, not {headers[key]}")
        if key in headers and headers[key][1].itemsize // 4 > MAX_RECORD_CHARS:
            raise ValueError(f"Trajectory.load: {path}: {key} is longer than {MAX_RECORD_CHARS} characters")
    if str(npz_member(archive, "format")) != FORMAT:
        raise ValueError(f"Trajectory.load: {path} is not a ballenv trajectory (format is not {FORMAT!r})")
    if "version" in missing or headers["version"] != ((), np.dtype(np.int64)):
        raise ValueError(f"Trajectory.load: {path} has no int64 layout version, this ballenv reads {VERSION}")
    version = int(npz_member(archive, "version"))
    if version != VERSION:
        raise ValueError(
            f"Trajectory.load: {path} has layout version {version}, this ballenv reads {VERSION}"
        )
    if missing:
        raise ValueError(f"Trajectory.load: {path} lacks {', '.join(missing)}")


def _records(path: pathlib.Path, archive: zipfile.ZipFile) -> tuple[Scene, dict[str, Any]]:
    """The scene (validated by ``Scene`` itself) and the statistics' fields."""
    try:
        scene = scene_from_dict(json.loads(str(npz_member(archive, "scene"))))
        stats = json.loads(str(npz_member(archive, "stats")))
        if not isinstance(stats, dict) or set(stats) != {f.name for f in dataclasses.fields(SimulationStats)}:
            raise ValueError("the statistics' fields are not SimulationStats'")
        SimulationStats(**{**stats, "effects": tuple(stats["effects"])})
    except (ValueError, TypeError, KeyError, AttributeError, RecursionError) as err:
        raise ValueError(f"Trajectory.load: {path} has an invalid scene or stats record ({err})") from err
    return scene, stats


def _check_arrays(path: pathlib.Path, headers: dict[str, Any], scene: Scene, max_bytes: int) -> None:
    """Every array float64 and of the shape the scene and the record count give, and all of them
    together within ``max_bytes`` (decompressed), before any is read."""
    n_records = headers["t"][0][0] if len(headers["t"][0]) == 1 else -1
    n_rings, n_nodes = len(scene.rings), scene.rings[0].n_nodes
    shapes = {
        "t": (n_records,),
        "x": (n_records, n_rings, n_nodes, 2),
        "v": (n_records, n_rings, n_nodes, 2),
        "pressure": (n_records, n_rings),
        "contact_force": (n_records, n_rings, n_nodes, 2),
        "event_table": (headers["event_table"][0][0] if headers["event_table"][0] else -1, 4),
    }
    total = 0
    for key, shape in shapes.items():
        got, dtype = headers[key]
        if got != shape or -1 in shape:
            raise ValueError(f"Trajectory.load: {path}: {key} has shape {got}, expected {shape}")
        if dtype != np.dtype(np.float64):
            raise ValueError(f"Trajectory.load: {path}: {key} has dtype {dtype}, expected float64")
        total += int(np.prod(shape)) * 8
    if total > max_bytes:
        raise ValueError(
            f"Trajectory.load: {path} declares {total} bytes of arrays, more than max_bytes = {max_bytes}"
        )
