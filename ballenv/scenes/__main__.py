"""Run a named scene and write its figure, video, measured numbers and trajectories.

    python -m ballenv.scenes --list
    python -m ballenv.scenes NAME [NAME ...] --out DIR [--fidelity balanced] [--reduced] [--video mp4]
    python -m ballenv.scenes vibrating-plate --out DIR --ray local  # its grid as Ray tasks

Writes, in DIR: ``NAME.png`` (the figure), ``NAME.gif`` and ``NAME.mp4`` (the video: a GIF for pages
that play only GIFs inline, the MP4 in full colour), ``NAME.json`` (parameters and measured numbers,
SI units) and ``NAME-LABEL.npz`` per simulation (``Trajectory.load``; replay with
``python -m ballenv.viewer DIR/NAME-LABEL.npz -o replay.html``). ``all`` runs every scene.
"""

import argparse
import json
import os
import pathlib
import re
import sys
import time

from ..cluster import check_cluster
from ..files import write_text
from ..video import FORMATS
from . import SCENES, get, run


def _slug(label):
    return re.sub(r"[^A-Za-z0-9.+-]+", "_", label).strip("_")


def _jsonable(value):
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_jsonable(v) for v in value]
    if hasattr(value, "tolist"):
        return value.tolist()
    return value


def run_one(
    name, out, fidelity="balanced", reduced=False, video=FORMATS, save=True, frames=120, progress=True,
    cluster=None,
):  # fmt: skip
    """Run scene ``name`` (its parameter grid, if it has one, on ``cluster``: :func:`.run`) and
    write its files into ``out``: the figure, the video in each format of ``video`` ("gif", "mp4";
    none: ``()``), the numbers and, with ``save``, the trajectories. Returns the written paths."""
    from .animate import write_videos
    from .figures import plot

    info = get(name)
    out = pathlib.Path(out)
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    result = run(name, fidelity=fidelity, reduced=reduced, progress=progress, cluster=cluster)
    wall = time.perf_counter() - start
    paths = [plot(result, out / f"{name}.png")]
    if video and result.animate:
        trajs = [result.trajectories[label] for label in result.animate]
        videos = [out / f"{name}.{fmt}" for fmt in video]
        paths += write_videos(trajs, videos, labels=list(result.animate), n_frames=frames, progress=progress)
    record = {
        "scene": name,
        "figure": info.figure,
        "fidelity": fidelity,
        "reduced": reduced,
        "wall_time_s": wall,
        "parameters": _jsonable(result.parameters),
        "metrics": _jsonable(result.metrics),
    }
    write_text(out / f"{name}.json", json.dumps(record, indent=1))
    paths.append(out / f"{name}.json")
    if save:
        for label, traj in result.trajectories.items():
            paths.append(traj.save(out / f"{name}-{_slug(label)}.npz"))
    return paths


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="python -m ballenv.scenes",
        description="Run named scenes: figure (PNG), video (GIF, MP4), numbers (JSON), trajectories (NPZ).",
    )
    parser.add_argument("names", nargs="*", metavar="NAME", help="scene name(s), or 'all'; see --list")
    parser.add_argument("--list", action="store_true", help="list the scenes and exit")
    parser.add_argument("--out", default="out/scenes", help="output folder (default: out/scenes)")
    parser.add_argument("--fidelity", default="balanced", choices=("fast", "balanced", "accurate"))
    parser.add_argument("--reduced", action="store_true", help="fewer cases (as the tests run them)")
    parser.add_argument(
        "--video",
        default="both",
        choices=(*FORMATS, "both"),
        help="video format (default: both, GIF and MP4)",
    )
    parser.add_argument("--no-video", action="store_true", help="write no video")
    parser.add_argument("--no-trajectories", action="store_true", help="do not save the .npz trajectories")
    parser.add_argument("--frames", type=int, default=120, help="frames of the video (default 120)")
    parser.add_argument(
        "--ray",
        dest="cluster",
        metavar="ADDRESS",
        default=None,
        help="run the scenes' parameter grids as Ray tasks: 'local' (a cluster on this machine), 'auto' "
        "or a cluster's address (pip install 'ballenv[ray]')",
    )
    args = parser.parse_args(argv)
    if args.list or not args.names:
        width = max(len(n) for n in SCENES)
        for info in SCENES.values():
            print(f"{info.name:<{width}}  {info.figure:<7} {info.summary}")
        return 0
    names = list(SCENES) if args.names == ["all"] else args.names
    for name in names:
        try:
            get(name)
        except ValueError as err:
            parser.error(str(err))
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    for name in names:
        print(f"== {name}", flush=True)
        paths = run_one(
            name,
            args.out,
            fidelity=args.fidelity,
            reduced=args.reduced,
            video=() if args.no_video else FORMATS if args.video == "both" else (args.video,),
            save=not args.no_trajectories,
            frames=args.frames,
            cluster=check_cluster(args.cluster),
        )
        for p in paths:
            print(f"wrote {p}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
