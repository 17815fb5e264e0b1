"""Videos of trajectories: frames drawn by :mod:`ballenv.draw`, written as MP4 or GIF by
:mod:`ballenv.video`.

Each panel shows one trajectory in a fixed view around everything it visits: the grounds (grey
half-planes), the rings (their centrelines), the ground reaction per node (blue, 2 mm per N) and
the time and gauge pressure. Several trajectories play side by side on one time axis.
"""

import numpy as np

from ..draw import STYLE, Canvas, View
from ..video import write_video

PANEL = 320  # pixels, panel height
GAP = 4  # pixels of white between panels
TEXT_SIZE = 10  # pixels
SHORTEST_S = 4.0  # s: a shorter trajectory plays slowed down to last this long


class Panel:
    """Maps one trajectory's metres to pixels (y up). The view holds everything the trajectory
    visits, with a margin; when that is more than ``FOLLOW`` radii across, a view 5 radii high
    follows the rings' centre instead (a ball rolling down a long slope)."""

    FOLLOW = 8.0

    def __init__(self, traj, height=PANEL, style=STYLE):
        radius = max(r.radius for r in traj.scene.rings)
        margin = 0.6 * radius
        pts = traj.x.reshape(-1, 2)
        lo = pts.min(axis=0) - margin
        hi = pts.max(axis=0) + margin
        if traj.scene.grounds and not np.any(hi - lo > self.FOLLOW * radius):
            lo[1] = min(lo[1], min(g.height for g in traj.scene.grounds) - 0.5 * margin)
        span = hi - lo
        self.traj = traj
        self.height = height
        self.style = style
        self.follow = bool(np.any(span > self.FOLLOW * radius))
        if self.follow:
            self.scale = height / (5.0 * radius)
            self.width = int(1.4 * height)
        else:
            self.scale = height / span[1]
            self.width = int(max(0.5 * height, min(3 * height, span[0] * self.scale)))
            self.centre = (0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]))

    def view(self, k):
        """The view of record ``k``: fixed, or centred on the rings when following them."""
        centre = self.traj.x[k].reshape(-1, 2).mean(axis=0) if self.follow else self.centre
        return View.centred(self.width, self.height, self.scale, centre)

    def draw(self, k, label=None):
        """The panel's (height, width, 3) uint8 image at record ``k``, ``label`` at its foot."""
        tr = self.traj
        canvas = Canvas(self.view(k), self.style)
        for g in tr.scene.grounds:
            canvas.ground(g.angle, g.height, g.x)
        for r in range(tr.x.shape[1]):
            canvas.ring(tr.x[k, r], r)
            canvas.forces(tr.x[k, r], tr.contact_force[k, r])
        p = ", ".join(f"{q / 1e3:.1f}" for q in tr.pressure[k])
        canvas.text([f"t = {tr.t[k]:.3f} s  p = {p} kPa"], at=(6, 4), size=TEXT_SIZE)
        if label:
            canvas.text([label], at=(6, self.height - 16), size=TEXT_SIZE)
        return canvas.array()


def frame_indices(t, times):
    """Index of the last record at or before each of ``times`` (s) in the record times ``t``."""
    return np.clip(np.searchsorted(t, times, side="right") - 1, 0, len(t) - 1)


def clip_seconds(trajectories, seconds=None):
    """The clip's length (s): ``seconds``, by default real time slowed down to last at least 4 s."""
    return seconds or max(SHORTEST_S, max(float(tr.t[-1]) for tr in trajectories))


def render_frames(trajectories, n_frames=120, labels=None, progress=False):
    """RGB frames ((H, W, 3) uint8 arrays) of ``trajectories`` side by side, ``n_frames`` evenly
    in time from 0 to the longest one's end."""
    panels = [Panel(tr) for tr in trajectories]
    t_end = max(float(tr.t[-1]) for tr in trajectories)
    times = np.linspace(0.0, t_end, n_frames)
    index = [frame_indices(tr.t, times) for tr in trajectories]
    labels = labels or [None] * len(panels)
    gap = np.full((PANEL, GAP, 3), 255, dtype=np.uint8)
    steps = range(n_frames)
    if progress:
        from tqdm.auto import tqdm

        steps = tqdm(steps, desc="frames", unit="frame")
    frames = []
    for j in steps:
        images = [panel.draw(int(index[i][j]), labels[i]) for i, panel in enumerate(panels)]
        parts = [part for image in images for part in (image, gap)][:-1]
        frames.append(np.concatenate(parts, axis=1))
    return frames


def write_videos(trajectories, paths, labels=None, n_frames=120, seconds=None, progress=False):
    """Draw ``trajectories`` side by side once and write the frames to each of ``paths`` (``.mp4``
    or ``.gif``), ``n_frames`` frames over ``seconds`` (s; default :func:`clip_seconds`). Returns
    the paths."""
    frames = render_frames(trajectories, n_frames, labels, progress)
    fps = n_frames / clip_seconds(trajectories, seconds)
    return [write_video(frames, path, fps) for path in paths]
