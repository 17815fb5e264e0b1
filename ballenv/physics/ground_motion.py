"""Prescribed rigid motion of the grounds: where a ground's surface is, and how fast it moves, at a time.

A ground ``g`` (a row of ``Model.grounds``, columns ``layout.GROUND``) is the half-plane
``n . x >= d(t)`` with a fixed unit normal ``n`` and the offset (m)

    d(t) = d0 + (n . u) t + A sin(omega t),          omega = 2 pi f,

a rigid motion with the constant velocity ``u`` (m/s; along the surface a conveyor belt, along
``n`` a rising or sinking plate) plus an oscillation along ``n`` of amplitude ``A`` (m) and
frequency ``f`` (Hz). Its surface moves with the velocity (m/s) and normal acceleration (m/s^2)

    w(t) = u + A omega cos(omega t) n,          a_n(t) = -A omega^2 sin(omega t).

The tangential part of ``w`` is the constant ``t . u``. A ground that does not move (``u = 0``,
``A = 0``) has ``d(t) = d0``, ``w = 0`` and ``a_n = 0`` exactly, so a scene of fixed grounds steps
bit for bit as before. The stepper writes the grounds at a trial step's start and end times into
the workspace (:func:`ground_surfaces`, rows ``layout.SURFACE``); the contact code reads those.
"""

import math
from typing import TYPE_CHECKING

import numpy as np

from .jit import kernel
from .layout import (
    GROUND,
    GROUND_AMPLITUDE,
    GROUND_ANGULAR_FREQUENCY,
    GROUND_FRICTION,
    GROUND_NORMAL,
    GROUND_OFFSET,
    GROUND_VELOCITY,
    SURFACE,
    SURFACE_FRICTION,
    SURFACE_NORMAL,
    SURFACE_NORMAL_ACCELERATION,
    SURFACE_OFFSET,
    SURFACE_VELOCITY,
)

if TYPE_CHECKING:
    from .scene import Ground, Scene


def ground_array(grounds: "tuple[Ground, ...]") -> np.ndarray:
    """(G, ``GROUND.size``) rows of ``grounds``: normal ``n = (-sin a, cos a)``, offset
    ``d0 = n . (x_g, height)`` (the surface passes through the ground's point (x, height) at
    t = 0), friction, velocity ``u``, amplitude ``A`` and angular frequency ``2 pi f``."""
    out = np.zeros((len(grounds), GROUND.size))
    for k, g in enumerate(grounds):
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
    """Rows ``out[g]`` (columns ``layout.SURFACE``) of every ground of ``grounds`` (columns
    ``layout.GROUND``) at time ``t`` (s): normal, ``d(t)``, friction, ``w(t)`` and ``a_n(t)`` (module
    doc). A term of a motion the ground does not have is not added (not even as a zero)."""
    for g in range(grounds.shape[0]):
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
        out[g, SURFACE_VELOCITY] = wx
        out[g, SURFACE_VELOCITY + 1] = wy
        out[g, SURFACE_NORMAL_ACCELERATION] = an


def grounds_move(scene: "Scene") -> bool:
    """A ground of the scene moves (a velocity or an oscillation)."""
    return any(g.moves for g in scene.grounds)
