"""Trajectory.save / Trajectory.load: exact round trip, documented layout, clear errors."""

import json

import numpy as np
import pytest

from ballenv.physics import Ground, Ring, Scene, Trajectory, simulate


@pytest.fixture(scope="module")
def traj():
    rings = [
        Ring(n_nodes=16, pressure=20e3, position=(-0.25, 0.3), velocity=(1.0, 0.0), angular_velocity=3.0),
        Ring(n_nodes=16, pressure=None, position=(0.25, 0.3), velocity=(-1.0, 0.0), thickness=4e-3),
    ]
    scene = Scene(
        rings=rings,
        grounds=[Ground(friction=0.4), Ground(angle=np.pi / 2, x=1.0)],
        gravity=(0.5, -9.81),
        damping=3.0,
        adaptive=True,
        dt=1e-2,
        impulse_tol=5e-3,
    )
    return simulate(scene, 0.4, output_dt=2e-3)


def test_round_trip_is_exact(traj, tmp_path):
    assert any(k == "touchdown" for _, _, k in traj.events)
    path = traj.save(tmp_path / "run")
    assert path.name == "run.npz"
    back = Trajectory.load(path)
    for name in ("t", "x", "v", "pressure", "contact_force", "event_table"):
        a, b = getattr(traj, name), getattr(back, name)
        assert a.dtype == b.dtype and np.array_equal(a, b), name
    assert back.events == traj.events
    assert back.scene == traj.scene
    assert back.stats == traj.stats
    np.testing.assert_array_equal(back.apexes(), traj.apexes())


def test_layout_is_plain_numpy(traj, tmp_path):
    path = traj.save(tmp_path / "run.npz")
    with np.load(path, allow_pickle=False) as archive:
        assert str(archive["format"]) == "ballenv.trajectory" and int(archive["version"]) == 1
        assert archive["x"].shape == (len(traj.t), 2, 16, 2)
        scene = json.loads(str(archive["scene"]))
        assert scene["rings"][1]["pressure"] is None and scene["gravity"] == [0.5, -9.81]
        assert scene["grounds"][1]["x"] == 1.0


def test_bad_files_raise_clear_errors(traj, tmp_path):
    with pytest.raises(FileNotFoundError, match="no such file"):
        Trajectory.load(tmp_path / "missing.npz")
    text = tmp_path / "notes.npz"
    text.write_text("not an archive")
    with pytest.raises(ValueError, match="not a .npz archive"):
        Trajectory.load(text)
    foreign = tmp_path / "foreign.npz"
    np.savez(foreign, a=np.zeros(3))
    with pytest.raises(ValueError, match="not a ballenv trajectory"):
        Trajectory.load(foreign)
    good = dict(np.load(traj.save(tmp_path / "good.npz")))
    del good["v"]
    np.savez(tmp_path / "partial.npz", **good)
    with pytest.raises(ValueError, match="lacks v"):
        Trajectory.load(tmp_path / "partial.npz")
    good = dict(np.load(tmp_path / "good.npz"))
    good["x"] = good["x"][:, :, :8]
    np.savez(tmp_path / "shape.npz", **good)
    with pytest.raises(ValueError, match="x has shape"):
        Trajectory.load(tmp_path / "shape.npz")
