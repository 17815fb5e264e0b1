"""Events located inside an accepted step: touchdown, lift-off and apex.

Rows of the event buffer: ``(t (s), ring, kind, centre-of-mass height (m))`` (``base.layout.EVENT``) with
kind ``base.layout.EVENT_KINDS`` (0 = touchdown, 1 = liftoff, 2 = apex).

* apex: the vertical centre-of-mass velocity changes sign from up to down within the step; its time
  by linear interpolation of that velocity, its height by the cubic Hermite interpolant of the
  centre-of-mass height (values and velocities at both ends), so the bounce height is exact to the
  integrator's order, not to the output sampling;
* touchdown: the ring had no node on a ground and now has; time from the path of the first node to
  touch relative to the surface (``phi0 + s h (v_n - w_n) = 0``, distance ``phi0`` and velocities at
  the step's start);
* lift-off: the last constraint was released; time = the end of the step (steps are short in contact).
"""

import numpy as np

from ..base.geometry import centre_of_mass
from ..base.jit import kernel
from ..base.layout import (
    EVENT_APEX,
    EVENT_HEIGHT,
    EVENT_KIND,
    EVENT_KINDS,
    EVENT_LIFTOFF,
    EVENT_RING,
    EVENT_T,
    EVENT_TOUCHDOWN,
)
from ..ground.contact import FREE, deepest_ground, frame, surface_velocity

__all__ = ["EVENT_APEX", "EVENT_KINDS", "EVENT_LIFTOFF", "EVENT_TOUCHDOWN", "detect_events", "event_list"]


@kernel
def _height(x, v):
    """Centre-of-mass height (m) and vertical velocity (m/s)."""
    _, cy, _, vy = centre_of_mass(x, v)
    return cy, vy


@kernel
def _hermite(y0, y1, d0, d1, s):
    """Cubic Hermite on [0, 1] with end values y0, y1 and end slopes d0, d1 (per unit s)."""
    s2 = s * s
    s3 = s2 * s
    return (2 * s3 - 3 * s2 + 1) * y0 + (s3 - 2 * s2 + s) * d0 + (-2 * s3 + 3 * s2) * y1 + (s3 - s2) * d1


@kernel
def _write(events, n_events, t, ring, kind, height):
    """Write event row ``n_events`` (columns ``base.layout.EVENT``); return the new count."""
    events[n_events, EVENT_T] = t
    events[n_events, EVENT_RING] = ring
    events[n_events, EVENT_KIND] = kind
    events[n_events, EVENT_HEIGHT] = height
    return n_events + 1


@kernel
def detect_events(model, surface, state, trial, t, h, events, n_events):
    """Append the events of the step ``state -> trial`` over ``[t, t + h]``; return the new count.
    ``surface``: the grounds at ``t`` (rows ``base.layout.SURFACE``)."""
    n_rings = state.x.shape[0]
    n_nodes = state.x.shape[1]
    contact = model.grounds.shape[0] > 0
    for r in range(n_rings):
        y0, vy0 = _height(state.x[r], state.v[r])
        y1, vy1 = _height(trial.x[r], trial.v[r])
        if contact:
            before = 0
            after = 0
            for i in range(n_nodes):
                if state.active[r, i] != FREE:
                    before += 1
                if trial.active[r, i] != FREE:
                    after += 1
            if before == 0 and after > 0:
                s_first = 1.0
                for i in range(n_nodes):
                    if trial.active[r, i] == FREE:
                        continue
                    g, phi0 = deepest_ground(surface, state.x[r, i, 0], state.x[r, i, 1])
                    x, y = state.x[r, i, 0], state.x[r, i, 1]
                    nx, ny, _ = frame(surface, g, x, y)
                    wx, wy = surface_velocity(surface, g, x, y)
                    wn = wx * nx + wy * ny
                    vn = nx * state.v[r, i, 0] + ny * state.v[r, i, 1] - wn
                    if vn < 0.0:
                        s_first = min(s_first, max(0.0, phi0 / (-vn * h)))
                s_first = min(s_first, 1.0)
                n_events = _write(
                    events,
                    n_events,
                    t + s_first * h,
                    r,
                    EVENT_TOUCHDOWN,
                    _hermite(y0, y1, vy0 * h, vy1 * h, s_first),
                )
            elif before > 0 and after == 0:
                n_events = _write(events, n_events, t + h, r, EVENT_LIFTOFF, y1)
        if vy0 > 0.0 and vy1 <= 0.0:
            s = vy0 / (vy0 - vy1)
            n_events = _write(
                events, n_events, t + s * h, r, EVENT_APEX, _hermite(y0, y1, vy0 * h, vy1 * h, s)
            )
    return n_events


def event_list(rows):
    """Event rows -> list of (t, ring, kind) tuples."""
    rows = np.asarray(rows)
    return [(float(row[EVENT_T]), int(row[EVENT_RING]), EVENT_KINDS[int(row[EVENT_KIND])]) for row in rows]
