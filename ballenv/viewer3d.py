"""The 3-D replay viewer: one self-contained HTML file that plays a 3-D ball's trajectory.

    python -m ballenv.viewer3d TRAJ.npz -o replay.html [--max-frames 1000]

``TRAJ.npz`` is a :func:`ballenv.shell_files.save` file; :func:`write_html` writes the page of a
trajectory in memory. The page needs no network and no server: three.js (shipped with the package
in ``ballenv/assets/three``, with its licence) and the player (``ballenv/assets/viewer3d.js``) are
inlined as ES modules, and the data as JSON with float32 / uint32 arrays in base64. It shows the
shaded ball(s), coloured by gauge pressure with a legend of the range (kPa), the grounds with a
grid, the drums, and below, each ball's gauge pressure over time with a cursor. Controls: an orbit
camera (drag, wheel), play/pause (space), a scrub bar, playback speed (0.05x-2x of real time),
step buttons (arrow keys), "follow" (the camera keeps the balls' centre in view). Playback follows
the recorded times, so adaptive-step records play at their true pace.

For tests and scripts, as the 2-D viewer: ``#frame=K`` in the URL opens record K;
``window.ballViewer`` has ``setFrame(k)``, ``play()``, ``pause()``, ``frame`` and ``nFrames``; the
element ``#status`` carries ``data-frame`` and ``data-t`` (s) of the shown record.
"""

from __future__ import annotations

import argparse
import base64
import html
import json
import math
import os
import pathlib
import re
import sys
from functools import cache
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from . import shell_files
from .files import write_text
from .shell.simulation import Trajectory
from .shell.skin.mesh import icosphere
from .viewer import SCRIPT_ESCAPES, select_frames

ASSETS = pathlib.Path(__file__).resolve().parent / "assets"
THREE_JS = ASSETS / "three" / "three-orbit.min.js"  # three.js with OrbitControls, one ES module
PLAYER_JS = ASSETS / "viewer3d.js"
# gauge pressure, low to high (a blue-to-red map that is never grey, so the ball stands out)
COLORMAP = ("#2c7bb6", "#00a6ca", "#00ccbc", "#90eb9d", "#f9d057", "#f29e2e", "#e76818", "#d7191c")
LINES = ("#c83c28", "#2864c8", "#28a050", "#a028a0")  # the pressure plot's line per ball
BACKGROUND = "#f4f4f0"
GROUND = "#c8c8bf"
GRID_LINE = "#8c8c84"


def _b64(array: ArrayLike, dtype: str = "<f4") -> str:
    """``array`` as base64 of its little-endian ``dtype`` bytes (C order)."""
    return base64.b64encode(np.ascontiguousarray(array, dtype=dtype).tobytes()).decode("ascii")


def _up(gravity: tuple[float, float, float]) -> list[float]:
    """The unit vector against gravity (m/s^2), +z without gravity."""
    g = np.asarray(gravity, dtype=float)
    norm = float(np.linalg.norm(g))
    return [0.0, 0.0, 1.0] if norm == 0.0 else [float(c) for c in -g / norm]


def viewer_data(traj: Trajectory, max_frames: int = 1000, title: str | None = None) -> dict[str, Any]:
    """The JSON-ready dict the page plays: records (at most ``max_frames``, evenly in time), the
    mesh's triangles, grounds, drums, events and colours (SI units)."""
    idx = select_frames(traj.t, max_frames)
    scene = traj.scene
    k = scene.shells[0].subdivisions
    extent = float(np.ptp(traj.x.reshape(-1, 3), axis=0).max()) if traj.x.size else 1.0
    extent = max(extent, 4 * max(s.radius for s in scene.shells))
    return {
        "title": title or "ballenv 3-D trajectory",
        "nFrames": len(idx),
        "nShells": int(traj.x.shape[1]),
        "nVertices": int(traj.x.shape[2]),
        "t": _b64(traj.t[idx]),
        "x": _b64(traj.x[idx]),
        "p": _b64(traj.pressure[idx]),
        "triangles": _b64(icosphere(k).triangles, "<u4"),
        "radius": [s.radius for s in scene.shells],
        "up": _up(scene.gravity_vector),
        "grounds": [{"normal": list(g.normal), "height": g.height} for g in scene.grounds],
        "drums": [
            {"centre": list(d.centre), "axis": list(d.axis), "radius": d.radius, "inside": d.inside}
            for d in scene.drums
        ],
        "events": [[float(t), int(s), kind, float(z)] for t, s, kind, z in traj.events],
        "gridStep": 10.0 ** math.floor(math.log10(extent / 4)),
        "colormap": list(COLORMAP),
        "lines": list(LINES),
        "background": BACKGROUND,
        "ground": GROUND,
        "gridLine": GRID_LINE,
        "info": (
            f"{len(scene.shells)} ball(s), subdivisions {k} ({traj.x.shape[2]} vertices), "
            f"{scene.integrator}, {traj.stats.steps} steps, {len(traj.t)} records"
            + (f" (showing {len(idx)})" if len(idx) < len(traj.t) else "")
        ),
    }


PAGE = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>__TITLE__</title>
<style>
body{font:14px system-ui,sans-serif;margin:12px;background:#fafaf7;color:#222}
#controls{display:flex;gap:8px;align-items:center;margin:6px 0}
#scrub{flex:1}
canvas{background:#fff;border:1px solid #ccc;display:block}
#status,#readout{font-family:monospace}
#legend{display:flex;gap:6px;align-items:center;font-size:12px}
#legend-bar{width:220px;height:12px;border:1px solid #999}
</style></head><body>
<h3 id="title">__TITLE__</h3>
<div id="info"></div>
<div id="legend">gauge pressure
<span id="legend-lo"></span><span id="legend-bar"></span><span id="legend-hi"></span>
&nbsp; <span id="readout"></span></div>
<canvas id="scene" width="900" height="520"></canvas>
<div id="controls">
<button id="play">play</button>
<button id="back">&#9664;</button><button id="fwd">&#9654;</button>
<input id="scrub" type="range" min="0" max="0" value="0">
<label>speed <select id="speed">
<option value="0.05">0.05x</option><option value="0.1">0.1x</option>
<option value="0.25" selected>0.25x</option><option value="0.5">0.5x</option>
<option value="1">1x</option><option value="2">2x</option></select></label>
<label><input id="follow" type="checkbox"> follow</label>
<span id="status" data-frame="-1" data-t="">loading</span>
</div>
<canvas id="plot" width="900" height="140"></canvas>
<script id="data" type="application/json">__DATA__</script>
<script type="importmap">__IMPORTS__</script>
<script type="module">__PLAYER__</script>
</body></html>
"""


@cache
def _module_url(path: pathlib.Path) -> str:
    """The ES module at ``path`` as a ``data:`` URL (base64: nothing in it can end the page's script)."""
    return "data:text/javascript;base64," + base64.b64encode(path.read_bytes()).decode("ascii")


def page(data: dict[str, Any]) -> str:
    """The HTML page of ``data`` (:func:`viewer_data`): the title HTML-escaped, the data as JSON with
    ``<``, ``>`` and ``&`` escaped, three.js as a ``data:`` URL in an import map, and the player's
    module, all put in one pass over the template (a placeholder inside the title or the data is
    text, never a place to fill)."""
    player = PLAYER_JS.read_text(encoding="utf-8")
    if "</script" in player.lower():
        raise ValueError(f"{PLAYER_JS} holds '</script', which would end the page's script")
    fills = {
        "__TITLE__": html.escape(str(data["title"])),
        "__DATA__": json.dumps(data).translate(SCRIPT_ESCAPES),
        "__IMPORTS__": json.dumps({"imports": {"three": _module_url(THREE_JS)}}),
        "__PLAYER__": player,
    }
    return re.sub("__TITLE__|__DATA__|__IMPORTS__|__PLAYER__", lambda m: fills[m.group(0)], PAGE)


def write_html(
    traj: Trajectory, path: str | os.PathLike[str], max_frames: int = 1000, title: str | None = None
) -> pathlib.Path:
    """Write the replay page of ``traj`` (a 3-D ball's trajectory) to ``path``, atomically; returns
    the path."""
    if not isinstance(max_frames, int) or isinstance(max_frames, bool) or max_frames < 2:
        raise ValueError(f"write_html.max_frames = {max_frames!r} is out of range: must be an integer >= 2")
    return write_text(path, page(viewer_data(traj, max_frames, title)))


def main(argv: list[str] | None = None) -> int:
    """The command line (module doc); returns the exit status (2: the file could not be read)."""
    parser = argparse.ArgumentParser(
        prog="python -m ballenv.viewer3d",
        description="Write a self-contained HTML page that replays a saved 3-D ball trajectory (.npz).",
    )
    parser.add_argument("trajectory", help="a ballenv.shell_files.save file (.npz)")
    parser.add_argument("-o", "--out", default="replay.html", help="HTML file to write (default replay.html)")
    parser.add_argument(
        "--max-frames", type=int, default=1000, help="records kept, evenly in time (default 1000)"
    )
    parser.add_argument("--title", default=None, help="page title (default: the file name)")
    args = parser.parse_args(argv)
    try:
        traj = shell_files.load(args.trajectory)
        path = write_html(traj, args.out, args.max_frames, args.title or pathlib.Path(args.trajectory).name)
    except (FileNotFoundError, ValueError) as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    size = path.stat().st_size / 1e6
    print(f"wrote {path} ({size:.2f} MB, {min(len(traj.t), args.max_frames)} records at most)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
