"""The replay page: self-contained, and it plays in a real headless browser (Debian's chromium)."""

import json

import numpy as np
import pytest

from ballenv.draw import STYLE
from ballenv.physics import Drum, Ground, Ring, Scene, Trajectory, simulate
from ballenv.viewer import main, select_frames, write_html

from .browser import run_chromium


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    ring = Ring(n_nodes=24, pressure=20e3, position=(0.0, 0.4))
    scene = Scene(rings=[ring], grounds=[Ground(friction=0.5)], adaptive=True, dt=1e-2, impulse_tol=5e-3)
    traj = simulate(scene, 0.5, output_dt=5e-3)
    return traj, traj.save(tmp_path_factory.mktemp("viewer") / "drop.npz")


def test_select_frames_keeps_ends_and_spreads_in_time():
    t = np.concatenate([np.linspace(0, 0.1, 500), np.linspace(0.1001, 1.0, 20)])
    idx = select_frames(t, 50)
    assert idx[0] == 0 and idx[-1] == len(t) - 1 and len(idx) <= 52
    assert np.all(np.diff(idx) > 0)


def test_page_is_self_contained(saved, tmp_path):
    _, path = saved
    assert main([str(path), "-o", str(tmp_path / "replay.html")]) == 0
    page = (tmp_path / "replay.html").read_text()
    for needle in ("http://", "https://", "<link", " src="):
        assert needle not in page, needle
    assert 'id="scrub"' in page and 'id="speed"' in page and 'id="play"' in page


def test_page_draws_in_the_renderers_style(saved, tmp_path):
    # colours, line width and force scale come from ballenv.draw.STYLE, inlined with the data
    page = write_html(saved[0], tmp_path / "replay.html").read_text()
    data, script = page.split('<script id="data" type="application/json">')[1].split("</script>", 1)
    assert json.loads(data)["style"] == STYLE.as_json()
    for colour in (*STYLE.as_json()["rings"], STYLE.as_json()["ground"], STYLE.as_json()["force"]):
        assert colour not in script, colour


def test_bad_trajectory_file_is_a_clear_error(tmp_path, capsys):
    bad = tmp_path / "bad.npz"
    bad.write_text("nope")
    assert main([str(bad), "-o", str(tmp_path / "r.html")]) == 2
    assert "not a .npz archive" in capsys.readouterr().err


def test_page_plays_in_headless_chromium(saved, tmp_path):
    traj, path = saved
    page = write_html(Trajectory.load(path), tmp_path / "replay.html")
    k = 40
    dom = run_chromium("--virtual-time-budget=2000", "--dump-dom", f"{page.as_uri()}#frame={k}")
    assert dom.returncode == 0, dom.stderr[-2000:]
    assert f'data-frame="{k}"' in dom.stdout, dom.stdout[-2000:]
    t_shown = float(dom.stdout.split('data-t="')[1].split('"')[0])
    assert t_shown == pytest.approx(traj.t[k], abs=1e-6)
    assert f"frame {k}/{len(traj.t) - 1}" in dom.stdout
    shot = tmp_path / "shot.png"
    res = run_chromium("--window-size=940,800", f"--screenshot={shot}", f"{page.as_uri()}#frame={k}")
    assert res.returncode == 0 and shot.exists(), res.stderr[-2000:]
    from PIL import Image

    pixels = np.asarray(Image.open(shot).convert("RGB")).reshape(-1, 3).astype(int)
    ring = np.all(np.abs(pixels - [200, 60, 40]) < 30, axis=1).sum()
    ground = np.all(np.abs(pixels - [150, 150, 150]) < 8, axis=1).sum()
    assert ring > 200 and ground > 10000, (ring, ground)


def test_page_draws_a_drum_as_ground_around_the_ring(tmp_path):
    """A drum the ring is inside is drawn as ground everywhere outside its circle (and the frames
    still play): the view fits the ring, so most of the picture's corners are the drum's wall."""
    ring = Ring(radius=0.05, n_nodes=24, position=(0.0, -0.19))
    scene = Scene(rings=[ring], drums=[Drum(radius=0.25, friction=0.5, angular_velocity=2.0)], dt=1e-3)
    traj = simulate(scene, 0.05, output_dt=5e-3)
    page = write_html(traj, tmp_path / "replay.html")
    assert json.loads(page.read_text().split('type="application/json">')[1].split("</script>")[0])[
        "drums"
    ] == [{"centre": [0.0, 0.0], "radius": 0.25, "inside": True}]
    shot = tmp_path / "shot.png"
    res = run_chromium("--window-size=940,800", f"--screenshot={shot}", f"{page.as_uri()}#frame=5")
    assert res.returncode == 0 and shot.exists(), res.stderr[-2000:]
    from PIL import Image

    pixels = np.asarray(Image.open(shot).convert("RGB")).reshape(-1, 3).astype(int)
    ring_pixels = np.all(np.abs(pixels - [200, 60, 40]) < 30, axis=1).sum()
    ground = np.all(np.abs(pixels - [150, 150, 150]) < 8, axis=1).sum()
    assert ring_pixels > 100 and ground > 10000, (ring_pixels, ground)


HOSTILE_TITLES = [
    '__DATA__<img src=x onerror="document.body.dataset.pwned=1">',
    "<!--<script>",
    "</script><script>document.body.dataset.pwned=1</script>",
    "__TITLE__ & </title><b>bold</b>",
]


@pytest.mark.parametrize("title", HOSTILE_TITLES)
def test_a_hostile_title_is_text_and_the_page_still_plays(saved, tmp_path, title):
    traj, path = saved
    page = write_html(Trajectory.load(path), tmp_path / "replay.html", title=title)
    source = page.read_text()
    data = source.split('<script id="data" type="application/json">')[1].split("</script>")[0]
    assert json.loads(data)["title"] == title  # the data round-trips, escaped for the script element
    assert "<" not in data and ">" not in data
    dom = run_chromium("--virtual-time-budget=2000", "--dump-dom", f"{page.as_uri()}#frame=5")
    assert dom.returncode == 0, dom.stderr[-2000:]
    assert 'data-frame="5"' in dom.stdout  # the player ran
    assert "data-pwned" not in dom.stdout and "<img" not in dom.stdout and "<b>" not in dom.stdout
