"""Saving and loading a 3-D ball's trajectory: exact round trips, atomic writes, and a loader that
trusts nothing in the file."""

import json

import numpy as np
import pytest

from ballenv import shell_files
from ballenv.shell import Ground, Scene, Shell
from ballenv.shell.scene import Drum

from .shell_drop import drop

ARRAYS = ("t", "x", "v", "contact_force", "pressure", "boundary_work")


def assert_same(a, b):
    for key in ARRAYS:
        np.testing.assert_array_equal(getattr(a, key), getattr(b, key), err_msg=key)
    assert a.events == b.events and a.stats == b.stats and a.scene == b.scene


def test_a_saved_trajectory_loads_back_exactly(tmp_path):
    traj = drop()
    path = shell_files.save(traj, tmp_path / "drop")
    assert path.name == "drop.npz" and [p.name for p in tmp_path.iterdir()] == ["drop.npz"]
    assert_same(shell_files.load(path), traj)


def test_every_scene_field_round_trips(tmp_path):
    """Several shells, a moving ground, a drum, gravity as a vector and a contact stiffness."""
    shells = [
        Shell(subdivisions=1, position=(0.0, 0.0, 0.5)),
        Shell(subdivisions=1, position=(0.5, 0.0, 0.5)),
    ]
    grounds = [Ground(normal=(0.1, 0.0, 1.0), height=-0.1, friction=0.3, amplitude=0.01, frequency=5.0)]
    drums = [Drum(radius=2.0, axis=(0.0, 1.0, 0.0), friction=0.2, angular_velocity=1.0, spin_up=0.5)]
    scene = Scene(
        shells=shells, grounds=grounds, drums=drums, gravity=(0.0, -1.0, -9.0), contact_stiffness=1e4,
        integrator="backward_euler", self_contact=True,
    )  # fmt: skip
    traj = drop(subdivisions=1, scene=scene)
    traj.x = np.concatenate([traj.x, traj.x + [0.5, 0.0, 0.0]], axis=1)
    for key in ("v", "contact_force"):
        setattr(traj, key, np.zeros_like(traj.x))
    traj.pressure = np.repeat(traj.pressure, 2, axis=1)
    traj.boundary_work = np.zeros((0, 0))  # as simulate() leaves it without moving grounds
    assert_same(shell_files.load(shell_files.save(traj, tmp_path / "two.npz")), traj)


def test_a_missing_or_foreign_file_is_a_clear_error(tmp_path):
    with pytest.raises(FileNotFoundError, match="no such file"):
        shell_files.load(tmp_path / "none.npz")
    (tmp_path / "text.npz").write_text("nope")
    with pytest.raises(ValueError, match="not a .npz archive"):
        shell_files.load(tmp_path / "text.npz")
    np.savez(tmp_path / "other.npz", t=np.zeros(3))
    with pytest.raises(ValueError, match="not a shell trajectory"):
        shell_files.load(tmp_path / "other.npz")


def rewrite(path, **members):
    """A copy of the archive at ``path`` with ``members`` (arrays) replaced or added."""
    with np.load(path, allow_pickle=False) as archive:
        arrays = {k: archive[k] for k in archive.files}
    arrays.update(members)
    out = path.with_name("bad.npz")
    np.savez(out, **arrays)
    return out


@pytest.mark.parametrize(
    "field, value",
    [("integrator", "</script><script>alert(1)</script>"), ("shells", []), ("rtol", float("nan"))],
)
def test_an_invalid_scene_is_rejected_by_its_constructors(tmp_path, field, value):
    path = shell_files.save(drop(), tmp_path / "drop.npz")
    scene = shell_files.scene_to_dict(drop().scene)
    scene[field] = value
    bad = rewrite(path, scene=np.array(json.dumps(scene)))
    with pytest.raises(ValueError, match="invalid scene or stats record"):
        shell_files.load(bad)


def test_the_loader_reads_no_pickles_and_checks_shapes_and_size(tmp_path):
    path = shell_files.save(drop(), tmp_path / "drop.npz")
    with pytest.raises(ValueError, match="x has shape"):
        shell_files.load(rewrite(path, x=np.zeros((26, 1, 42, 3))))
    with pytest.raises(ValueError, match="dtype"):
        shell_files.load(rewrite(path, t=np.zeros(26, dtype=np.float32)))
    with pytest.raises(ValueError, match="more than max_bytes"):
        shell_files.load(path, max_bytes=1000)
    pickled = np.array([{"a": 1}], dtype=object)  # np.savez stores it as a pickle
    for key in ("stats", "event_table"):
        with pytest.raises(ValueError, match=key):
            shell_files.load(rewrite(path, **{key: pickled}))


def test_events_of_unknown_kinds_or_shells_are_rejected(tmp_path):
    path = shell_files.save(drop(), tmp_path / "drop.npz")
    with pytest.raises(ValueError, match="unknown event kinds or shells"):
        shell_files.load(rewrite(path, event_table=np.array([[0.1, 3.0, 0.0, 0.2]])))
