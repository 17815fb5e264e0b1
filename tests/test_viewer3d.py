"""The 3-D replay page: self-contained (three.js inlined from the package), its data round-trips,
a hostile title stays text, and it draws the ball in a real headless browser (Debian's chromium)."""

import base64
import json
import re

import numpy as np
import pytest

from ballenv import shell_files
from ballenv.shell.skin.mesh import icosphere
from ballenv.viewer3d import THREE_JS, main, viewer_data, write_html

from .browser import run_chromium, screenshot_pixels
from .shell_drop import drop

# WebGL in headless chromium without a GPU: SwiftShader, asked for by name (the page is ours)
WEBGL = "--enable-unsafe-swiftshader"


@pytest.fixture(scope="module")
def traj():
    return drop()


@pytest.fixture(scope="module")
def page(traj, tmp_path_factory):
    return write_html(traj, tmp_path_factory.mktemp("viewer3d") / "replay.html")


def page_data(source):
    return json.loads(source.split('<script id="data" type="application/json">')[1].split("</script>")[0])


def floats(b64, dtype="<f4"):
    return np.frombuffer(base64.b64decode(b64), dtype=dtype)


def test_the_page_loads_nothing_from_the_network(page):
    source = page.read_text()
    for needle in ("http://", "https://", "<link", " src=", "//cdn", "fetch("):
        assert needle not in source, needle
    imports = json.loads(source.split('<script type="importmap">')[1].split("</script>")[0])["imports"]
    assert list(imports) == ["three"]  # one module, the package's own three.js, as a data: URL
    prefix = "data:text/javascript;base64,"
    assert imports["three"].startswith(prefix)
    assert base64.b64decode(imports["three"][len(prefix) :]) == THREE_JS.read_bytes()
    for control in ('id="scrub"', 'id="speed"', 'id="play"', 'id="plot"', 'id="legend-bar"'):
        assert control in source, control


def test_the_data_round_trips(page, traj):
    data = page_data(page.read_text())
    n, shells, vertices = traj.x.shape[:3]
    assert (data["nFrames"], data["nShells"], data["nVertices"]) == (n, shells, vertices)
    np.testing.assert_array_equal(floats(data["t"]), traj.t.astype("<f4"))
    np.testing.assert_array_equal(floats(data["x"]).reshape(traj.x.shape), traj.x.astype("<f4"))
    np.testing.assert_array_equal(floats(data["p"]).reshape(n, shells), traj.pressure.astype("<f4"))
    triangles = floats(data["triangles"], "<u4").reshape(-1, 3)
    np.testing.assert_array_equal(triangles, icosphere(2).triangles)
    assert data["up"] == [0.0, 0.0, 1.0]
    assert data["grounds"] == [{"normal": [0.0, 0.0, 1.0], "height": 0.0}]
    assert data["events"] == [list(e) for e in traj.events]


def test_max_frames_keeps_the_ends(traj):
    data = viewer_data(traj, max_frames=5)
    t = floats(data["t"])
    assert 2 <= data["nFrames"] <= 7 and t[0] == 0.0 and t[-1] == np.float32(traj.t[-1])
    with pytest.raises(ValueError, match="max_frames"):
        write_html(traj, "unused.html", max_frames=1)


def test_the_command_line_writes_the_page_of_a_saved_file(traj, tmp_path, capsys):
    saved = shell_files.save(traj, tmp_path / "drop.npz")
    assert main([str(saved), "-o", str(tmp_path / "r.html"), "--max-frames", "10"]) == 0
    assert page_data((tmp_path / "r.html").read_text())["title"] == "drop.npz"
    (tmp_path / "bad.npz").write_text("nope")
    assert main([str(tmp_path / "bad.npz"), "-o", str(tmp_path / "r2.html")]) == 2
    assert "not a .npz archive" in capsys.readouterr().err and not (tmp_path / "r2.html").exists()


HOSTILE_TITLE = '</script><script>document.body.dataset.pwned=1</script><img src=x onerror="x()"> & __DATA__'


def test_a_hostile_title_is_text_and_the_page_still_plays(traj, tmp_path):
    source = write_html(traj, tmp_path / "replay.html", title=HOSTILE_TITLE).read_text()
    data = source.split('<script id="data" type="application/json">')[1].split("</script>")[0]
    assert "<" not in data and ">" not in data and "&" not in data
    assert json.loads(data)["title"] == HOSTILE_TITLE
    dom = run_chromium(
        WEBGL, "--virtual-time-budget=3000", "--dump-dom", f"{(tmp_path / 'replay.html').as_uri()}#frame=3"
    )
    assert dom.returncode == 0, dom.stderr[-2000:]
    assert 'data-frame="3"' in dom.stdout, dom.stdout[-2000:]
    assert "data-pwned" not in dom.stdout and "<img" not in dom.stdout


def ball_pixels(pixels, colour):
    """(rows, columns) of the pixels within a shading's reach of ``colour`` (its hue kept)."""
    rgb = np.asarray(colour, dtype=float)
    scale = (pixels * rgb).sum(axis=2) / (rgb @ rgb)  # the brightness a light gives the colour
    near = np.linalg.norm(pixels - scale[..., None] * rgb, axis=2) < 25
    return np.nonzero(near & (scale > 0.35) & (scale < 1.6))


@pytest.mark.parametrize("frame, colour", [(0, (44, 123, 182)), (25, (215, 25, 28))])
def test_the_ball_is_drawn_in_headless_chromium(page, traj, tmp_path, frame, colour):
    """At the first record the ball has the low end's colour, at the last the high end's, and it
    is lower in the picture at the last (it fell); #status reports the record."""
    url = f"{page.as_uri()}#frame={frame}"
    dom = run_chromium(WEBGL, "--virtual-time-budget=3000", "--dump-dom", url)
    assert dom.returncode == 0, dom.stderr[-2000:]
    assert f'data-frame="{frame}"' in dom.stdout, dom.stdout[-2000:]
    t_shown = float(re.search(r'data-t="([^"]*)"', dom.stdout).group(1))
    assert t_shown == pytest.approx(traj.t[frame], abs=1e-6)
    shot = tmp_path / "shot.png"
    res = run_chromium(WEBGL, "--window-size=940,800", f"--screenshot={shot}", url)
    assert res.returncode == 0 and shot.exists(), res.stderr[-2000:]
    pixels = screenshot_pixels(shot)
    rows, cols = ball_pixels(pixels, colour)
    assert len(rows) > 3000, len(rows)  # a ball about 130 px across
    assert 300 < cols.mean() < 620, cols.mean()  # in the middle of the 900 px wide scene
    assert (rows.mean() < 300) if frame == 0 else (rows.mean() > 300), rows.mean()
    ground = np.all(np.abs(pixels - pixels[550, 100]) < 20, axis=2).sum()
    assert 80 < pixels[550, 100].mean() < 230 and ground > 20000, (pixels[550, 100], ground)
