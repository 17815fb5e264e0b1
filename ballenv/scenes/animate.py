"""Videos of trajectories: frames drawn with Pillow, written as an animated GIF.

Each panel shows one trajectory in a fixed view around everything it visits: the grounds (grey
half-planes), the rings (their centrelines), the ground reaction per node (blue, 2 mm per N) and
the time and gauge pressure. Several trajectories play side by side on one time axis.
"""

import math

import numpy as np

from ..render import BACKGROUND, FORCE, FORCE_SCALE, RING, TEXT

PANEL = 320  # pixels, panel height
GROUND = (150, 150, 150)  # lighter than the renderer's, the replay viewer's grey
RINGS = (RING, (40, 90, 200), (40, 150, 70), (150, 60, 160))


def _pil():
    try:
        from PIL import Image, ImageDraw
    except ImportError as err:  # pragma: no cover - depends on the installed extras
        raise ImportError("the scene videos need Pillow: pip install 'ballenv[plot]'") from err
    return Image, ImageDraw


class Panel:
    """Maps one trajectory's metres to pixels (y up). The view holds everything the trajectory
    visits, with a margin; when that is more than ``FOLLOW`` radii across, a view 5 radii high
    follows the rings' centre instead (a ball rolling down a long slope)."""

    FOLLOW = 8.0

    def __init__(self, traj, height=PANEL):
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
        self.follow = bool(np.any(span > self.FOLLOW * radius))
        if self.follow:
            self.scale = height / (5.0 * radius)
            self.width = int(1.4 * height)
        else:
            self.scale = height / span[1]
            self.width = int(max(0.5 * height, min(3 * height, span[0] * self.scale)))
            self.centre = (0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]))

    def _origin(self, k):
        if self.follow:
            cx, cy = self.traj.x[k].reshape(-1, 2).mean(axis=0)
        else:
            cx, cy = self.centre
        self.x0 = cx - 0.5 * self.width / self.scale
        self.y0 = cy - 0.5 * self.height / self.scale

    def px(self, p):
        return (float((p[0] - self.x0) * self.scale), float(self.height - (p[1] - self.y0) * self.scale))

    def draw(self, k):
        """The panel's image at record ``k``."""
        Image, ImageDraw = _pil()
        image = Image.new("RGB", (self.width, self.height), BACKGROUND)
        draw = ImageDraw.Draw(image)
        self._origin(k)
        tr = self.traj
        far = 4.0 * (self.width + self.height) / self.scale
        centre = np.array([self.x0, self.y0]) + 0.5 * np.array([self.width, self.height]) / self.scale
        for g in tr.scene.grounds:
            a = g.angle
            n = np.array([-math.sin(a), math.cos(a)])
            d = np.array([math.cos(a), math.sin(a)])
            base = np.array([g.x, g.height])
            base = base + d * ((centre - base) @ d)  # the surface's point nearest the view
            poly = [base - far * d, base + far * d, base + far * d - far * n, base - far * d - far * n]
            draw.polygon([self.px(q) for q in poly], fill=GROUND)
        for r in range(tr.x.shape[1]):
            pts = [self.px(q) for q in tr.x[k, r]]
            draw.line(pts + pts[:1], fill=RINGS[r % len(RINGS)], width=2)
            for q, f in zip(tr.x[k, r], tr.contact_force[k, r], strict=True):
                if f[0] != 0.0 or f[1] != 0.0:
                    draw.line([self.px(q), self.px(q + FORCE_SCALE * f)], fill=FORCE, width=2)
        p = ", ".join(f"{q / 1e3:.1f}" for q in tr.pressure[k])
        draw.text((6, 4), f"t = {tr.t[k]:.3f} s  p = {p} kPa", fill=TEXT)
        return image


def frame_indices(t, times):
    """Index of the last record at or before each of ``times`` (s) in the record times ``t``."""
    return np.clip(np.searchsorted(t, times, side="right") - 1, 0, len(t) - 1)


def render_frames(trajectories, n_frames=120, labels=None, progress=False):
    """RGB frames (PIL images) of ``trajectories`` side by side, ``n_frames`` evenly in time."""
    Image, ImageDraw = _pil()
    panels = [Panel(tr) for tr in trajectories]
    width = sum(p.width for p in panels) + 4 * (len(panels) - 1)
    t_end = max(float(tr.t[-1]) for tr in trajectories)
    times = np.linspace(0.0, t_end, n_frames)
    index = [frame_indices(tr.t, times) for tr in trajectories]
    frames = []
    steps = range(n_frames)
    if progress:
        from tqdm.auto import tqdm

        steps = tqdm(steps, desc="frames", unit="frame")
    for j in steps:
        image = Image.new("RGB", (width, PANEL), (255, 255, 255))
        offset = 0
        for i, panel in enumerate(panels):
            image.paste(panel.draw(int(index[i][j])), (offset, 0))
            if labels:
                draw = ImageDraw.Draw(image)
                draw.text((offset + 6, PANEL - 16), labels[i], fill=TEXT)
            offset += panel.width + 4
        frames.append(image)
    return frames


def write_gif(trajectories, path, labels=None, n_frames=120, duration=None, progress=False):
    """Write an animated GIF of ``trajectories`` (side by side) to ``path``; ``duration`` (s) of the
    whole clip (default: real time slowed so it lasts at least 4 s). Returns the path."""
    frames = render_frames(trajectories, n_frames, labels, progress)
    t_end = max(float(tr.t[-1]) for tr in trajectories)
    duration = duration or max(4.0, t_end)
    frames = [f.quantize(colors=32, dither=0) for f in frames]
    frames[0].save(
        path,
        save_all=True,
        append_images=frames[1:],
        duration=max(20, int(1000 * duration / len(frames))),
        loop=0,
        optimize=True,
    )
    return path
