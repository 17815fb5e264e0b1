"""Prescribed rigid motion of the grounds: where a ground's surface is, and how fast it moves, at a time.

A ground ``g`` (a row of ``Model.grounds``, columns ``base.layout.GROUND``) is the half-plane
``n . x >= d(t)`` with a fixed unit normal ``n`` and the offset (m)

    d(t) = d0 + (n . u) t + A sin(omega t),          omega = 2 pi f,

a rigid motion with the constant velocity ``u`` (m/s; along the surface a conveyor belt, along
``n`` a rising or sinking plate) plus an oscillation along ``n`` of amplitude ``A`` (m) and
frequency ``f`` (Hz). Its surface moves with the velocity (m/s) and normal acceleration (m/s^2)

    w(t) = u + A omega cos(omega t) n,          a_n(t) = -A omega^2 sin(omega t).

The tangential part of ``w`` is the constant ``t . u``. A ground that does not move (``u = 0``,
``A = 0``) has ``d(t) = d0``, ``w = 0`` and ``a_n = 0`` exactly, so a scene of fixed grounds steps
bit for bit as before. The stepper writes the grounds at a trial step's start and end times into
the workspace (:func:`ground_surfaces`, rows ``base.layout.SURFACE``); the contact code reads those.

A drum (``Scene.drums``, rows after the half-planes, kind ``GROUND_DRUM_INSIDE`` or
``GROUND_DRUM_OUTSIDE``) is the circle of centre ``c`` and radius ``R`` (m) with the rings inside
(``R - |x - c| >= 0``) or outside (``|x - c| - R >= 0``), turning about its fixed centre at the
angular velocity (rad/s, counter-clockwise positive)

    Omega(t) = Omega_0 min(1, t / T)          (T = 0: Omega_0 from the start),

a spin-up over ``T`` (s) to a constant speed. It has turned by the angle (rad)

    theta(t) = Omega_0 t^2 / (2 T)   for t < T,          Omega_0 (t - T / 2)   after,

and its surface at ``x`` moves with ``w(x, t) = Omega(t) e_z x (x - c) = Omega (-(y - c_y), x - c_x)``,
along the surface: the drum's normal velocity is 0, its geometry does not change.
"""

import math
from typing import TYPE_CHECKING

import numpy as np

from ..base.jit import kernel
from ..base.layout import (
    GROUND,
    GROUND_AMPLITUDE,
    GROUND_ANGULAR_FREQUENCY,
    GROUND_CENTRE,
    GROUND_DRUM_INSIDE,
    GROUND_DRUM_OUTSIDE,
    GROUND_FRICTION,
    GROUND_KIND,
    GROUND_NORMAL,
    GROUND_OFFSET,
    GROUND_PLANE,
    GROUND_RADIUS,
    GROUND_SPIN,
    GROUND_SPIN_UP,
    GROUND_VELOCITY,
    SURFACE,
    SURFACE_CENTRE,
    SURFACE_FRICTION,
    SURFACE_KIND,
    SURFACE_NORMAL,
    SURFACE_NORMAL_ACCELERATION,
    SURFACE_OFFSET,
    SURFACE_RADIUS,
    SURFACE_SPIN,
    SURFACE_TURN,
    SURFACE_VELOCITY,
)

if TYPE_CHECKING:
    from ..scene import Drum, Ground, Scene


def ground_array(grounds: "tuple[Ground, ...]", drums: "tuple[Drum, ...]" = ()) -> np.ndarray:
    """(G, ``GROUND.size``) rows of ``grounds`` then ``drums``. A half-plane: normal
    ``n = (-sin a, cos a)``, offset ``d0 = n . (x_g, height)`` (the surface passes through the
    ground's point (x, height) at t = 0), friction, kind ``GROUND_PLANE``, velocity ``u``, amplitude
    ``A`` and angular frequency ``2 pi f``. A drum: friction, kind, centre, radius, angular velocity
    and spin-up time (the normal and offset columns are 0: a drum's normal depends on the point)."""
    out = np.zeros((len(grounds) + len(drums), GROUND.size))
    for k, d in enumerate(drums, start=len(grounds)):
        out[k, GROUND_FRICTION] = d.friction
        out[k, GROUND_KIND] = GROUND_DRUM_INSIDE if d.inside else GROUND_DRUM_OUTSIDE
        out[k, GROUND_CENTRE : GROUND_CENTRE + 2] = d.centre
        out[k, GROUND_RADIUS] = d.radius
        out[k, GROUND_SPIN] = d.angular_velocity
        out[k, GROUND_SPIN_UP] = d.spin_up
    for k, g in enumerate(grounds):
        out[k, GROUND_KIND] = GROUND_PLANE
        nx, ny = -math.sin(g.angle), math.cos(g.angle)
        out[k, GROUND_NORMAL : GROUND_NORMAL + 2] = (nx, ny)
        out[k, GROUND_OFFSET] = nx * g.x + ny * g.height
        out[k, GROUND_FRICTION] = g.friction
        out[k, GROUND_VELOCITY : GROUND_VELOCITY + 2] = g.velocity
        out[k, GROUND_AMPLITUDE] = g.amplitude
        out[k, GROUND_ANGULAR_FREQUENCY] = 2.0 * math.pi * g.frequency
    return out


def surface_array(n_grounds: int) -> np.ndarray:
    """Zeroed (G, ``SURFACE.size``) rows for :func:`ground_surfaces`."""
    return np.zeros((n_grounds, SURFACE.size))


@kernel
def ground_surfaces(grounds, t, out):
    """Rows ``out[g]`` (columns ``base.layout.SURFACE``) of every ground of ``grounds`` (columns
    ``base.layout.GROUND``) at time ``t`` (s): normal, ``d(t)``, friction, ``w(t)`` and ``a_n(t)`` of a
    half-plane, ``Omega(t)`` and ``theta(t)`` of a drum (module doc). A term of a motion the ground
    does not have is not added (not even as a zero)."""
    for g in range(grounds.shape[0]):
        kind = grounds[g, GROUND_KIND]
        if kind != GROUND_PLANE:
            drum_surface(grounds, g, t, out)
            continue
        nx, ny = grounds[g, GROUND_NORMAL], grounds[g, GROUND_NORMAL + 1]
        ux, uy = grounds[g, GROUND_VELOCITY], grounds[g, GROUND_VELOCITY + 1]
        amplitude = grounds[g, GROUND_AMPLITUDE]
        omega = grounds[g, GROUND_ANGULAR_FREQUENCY]
        d = grounds[g, GROUND_OFFSET]
        un = nx * ux + ny * uy
        if un != 0.0:
            d += un * t
        wx, wy, an = ux, uy, 0.0
        if amplitude != 0.0:
            phase = omega * t
            sine = math.sin(phase)
            d += amplitude * sine
            wn = amplitude * omega * math.cos(phase)
            wx += wn * nx
            wy += wn * ny
            an = -amplitude * omega * omega * sine
        out[g, SURFACE_NORMAL] = nx
        out[g, SURFACE_NORMAL + 1] = ny
        out[g, SURFACE_OFFSET] = d
        out[g, SURFACE_FRICTION] = grounds[g, GROUND_FRICTION]
        out[g, SURFACE_KIND] = GROUND_PLANE
        out[g, SURFACE_VELOCITY] = wx
        out[g, SURFACE_VELOCITY + 1] = wy
        out[g, SURFACE_NORMAL_ACCELERATION] = an


@kernel(inline="always")
def drum_surface(grounds, g, t, out):
    """Row ``out[g]`` of drum ``g`` at time ``t`` (s): its kind, centre, radius and friction, its
    angular velocity ``Omega(t)`` (rad/s) and the angle ``theta(t)`` (rad) it has turned (module doc)."""
    out[g, SURFACE_NORMAL] = 0.0
    out[g, SURFACE_NORMAL + 1] = 0.0
    out[g, SURFACE_OFFSET] = 0.0
    out[g, SURFACE_FRICTION] = grounds[g, GROUND_FRICTION]
    out[g, SURFACE_KIND] = grounds[g, GROUND_KIND]
    out[g, SURFACE_CENTRE] = grounds[g, GROUND_CENTRE]
    out[g, SURFACE_CENTRE + 1] = grounds[g, GROUND_CENTRE + 1]
    out[g, SURFACE_RADIUS] = grounds[g, GROUND_RADIUS]
    out[g, SURFACE_VELOCITY] = 0.0
    out[g, SURFACE_VELOCITY + 1] = 0.0
    out[g, SURFACE_NORMAL_ACCELERATION] = 0.0
    spin = grounds[g, GROUND_SPIN]
    ramp = grounds[g, GROUND_SPIN_UP]
    if t < ramp:
        out[g, SURFACE_SPIN] = spin * t / ramp
        out[g, SURFACE_TURN] = 0.5 * spin * t * t / ramp
    else:
        out[g, SURFACE_SPIN] = spin
        out[g, SURFACE_TURN] = spin * (t - 0.5 * ramp)


def grounds_move(scene: "Scene") -> bool:
    """A ground of the scene moves (a velocity or an oscillation), or a drum turns."""
    return any(g.moves for g in scene.grounds) or any(d.moves for d in scene.drums)
