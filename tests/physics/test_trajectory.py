"""Trajectory.save / Trajectory.load: exact round trip, documented layout, clear errors."""

import io
import json
import resource
import subprocess
import sys
import time
import zipfile

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


def _variant(traj, tmp_path, name, **changes):
    """A copy of ``traj``'s file with arrays replaced (``None`` removes one)."""
    arrays = dict(np.load(traj.save(tmp_path / "base.npz")))
    for key, value in changes.items():
        if value is None:
            del arrays[key]
        else:
            arrays[key] = value
    path = tmp_path / name
    np.savez_compressed(path, **arrays)
    return path


def _bomb(tmp_path, traj, records):
    """A small archive whose ``x`` declares ``records`` records (a ``.npy`` header and a few zeros)."""
    good = dict(np.load(traj.save(tmp_path / "base.npz")))
    path = tmp_path / "bomb.npz"
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as out:
        for key, value in good.items():
            if key in ("t", "x", "v", "contact_force", "pressure"):
                shape = (records, *value.shape[1:])
                header = {"descr": "<f8", "fortran_order": False, "shape": shape}
                buffer = io.BytesIO()
                np.lib.format.write_array_header_2_0(buffer, header)
                out.writestr(key + ".npy", buffer.getvalue() + bytes(2**20))
            else:
                buffer = io.BytesIO()
                np.lib.format.write_array(buffer, value, allow_pickle=False)
                out.writestr(key + ".npy", buffer.getvalue())
    return path


def test_an_archive_declaring_huge_arrays_is_refused_before_anything_is_allocated(traj, tmp_path):
    path = _bomb(tmp_path, traj, records=4_000_000)  # about 4 GB declared, 60 kB on disk
    assert path.stat().st_size < 100_000
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    start = time.perf_counter()
    with pytest.raises(ValueError, match="declares .* bytes of arrays, more than max_bytes"):
        Trajectory.load(path)
    assert time.perf_counter() - start < 1.0
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before < 200_000  # kB: nothing big
    small = traj.save(tmp_path / "small.npz")
    with pytest.raises(ValueError, match="more than max_bytes = 1000"):
        Trajectory.load(small, max_bytes=1000)


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"x": "strings"}, "x has dtype <U7, expected float64"),
        ({"v": "complex"}, "v has dtype complex128, expected float64"),
        ({"format": "array"}, "format must be a string"),
        ({"version": "float"}, "no int64 layout version"),
        ({"scene": "nested"}, "invalid scene or stats record"),
        ({"stats": "list"}, "invalid scene or stats record"),
        ({"stats": "unknown field"}, "invalid scene or stats record"),
        ({"event_table": "ring 7"}, "unknown event kinds or rings"),
        ({"t": "2-D"}, "t has shape"),
    ],
)
def test_every_malformed_field_is_one_value_error_naming_the_file(traj, tmp_path, changes, message):
    good = dict(np.load(traj.save(tmp_path / "base.npz")))
    bad = {
        "strings": np.full(good["x"].shape, "strings"),
        "complex": good["v"].astype(complex),
        "array": np.array(["ballenv.trajectory", "x"]),
        "float": np.array(1.0),
        "nested": np.array("[" * 100_000 + "]" * 100_000),
        "list": np.array(json.dumps([1, 2])),
        "unknown field": np.array(json.dumps({**json.loads(str(good["stats"])), "extra": 1})),
        "ring 7": np.array([[0.1, 7.0, 0.0, 0.3]]),
        "2-D": good["t"][:, None],
    }
    key, kind = next(iter(changes.items()))
    path = _variant(traj, tmp_path, "bad.npz", **{key: bad[kind]})
    with pytest.raises(ValueError, match=message) as err:
        Trajectory.load(path)
    assert str(path) in str(err.value)


@pytest.mark.parametrize("damage", ["truncated", "corrupt deflate", "bad crc", "encrypted", "compression 99"])
def test_a_damaged_archive_is_a_value_error_not_a_zlib_or_zip_error(traj, tmp_path, damage):
    path = traj.save(tmp_path / "damaged.npz")
    data = bytearray(path.read_bytes())
    if damage == "truncated":
        data = data[: len(data) // 2]
    elif damage in ("encrypted", "compression 99"):  # the central directory's entry of the first member
        entry = data.index(b"PK\x01\x02")
        if damage == "encrypted":
            data[entry + 8] |= 1  # general purpose flag, bit 0 (zipfile: RuntimeError)
        else:
            data[entry + 10 : entry + 12] = (99).to_bytes(2, "little")  # (zipfile: NotImplementedError)
    else:
        with zipfile.ZipFile(path) as archive:
            info = archive.getinfo("x.npy")
        start = info.header_offset + 30 + len(info.filename) + len(info.extra)
        offset = start + (info.compress_size // 2 if damage == "bad crc" else 2)
        data[offset : offset + 64] = bytes(64) if damage == "bad crc" else b"\xff" * 64
    path.write_bytes(bytes(data))
    with pytest.raises(ValueError, match="Trajectory.load"):
        Trajectory.load(path)


def test_a_save_that_fails_midway_leaves_the_old_file_whole(traj, tmp_path, monkeypatch):
    path = traj.save(tmp_path / "kept.npz")
    before = path.read_bytes()
    import ballenv.physics.trajectory as module

    def interrupted(file, **arrays):
        np.savez(file, t=arrays["t"])  # a fragment, then the interruption
        raise KeyboardInterrupt

    monkeypatch.setattr(module.np, "savez_compressed", interrupted)
    with pytest.raises(KeyboardInterrupt):
        traj.save(path)
    monkeypatch.undo()
    assert path.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["kept.npz"]  # no temporary file left


KILLED_SAVE = """
import sys
import numpy as np
from ballenv.physics import Trajectory
traj = Trajectory.load(sys.argv[1])
traj.x = np.random.default_rng(0).normal(size=(4000, *traj.x.shape[1:]))  # slow to compress
traj.t = np.arange(4000.0)
traj.v = traj.contact_force = traj.x
traj.pressure = np.zeros((4000, traj.x.shape[1]))
print("saving", flush=True)
while True:
    traj.save(sys.argv[1])
"""


def test_a_process_killed_while_saving_leaves_a_loadable_file(traj, tmp_path):
    path = traj.save(tmp_path / "killed.npz")
    proc = subprocess.Popen([sys.executable, "-c", KILLED_SAVE, str(path)], stdout=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "saving"
    time.sleep(1.5)
    proc.kill()
    proc.wait()
    back = Trajectory.load(path)  # the old file or a whole new one, never a fragment
    assert back.x.shape[0] in (len(traj.t), 4000)
