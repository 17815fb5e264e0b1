"""The named hard cases of the stability suite, each a scene, an end time and optionally a start
state; every case is run with both contact methods and both integrators.

All use SI units. Unless a case says otherwise: a ring of radius 0.1 m, N = 32, E = 10 MPa,
h = 2 mm, b = 2 cm, rho = 1100 kg/m^3, 30 kPa, on flat ground with friction 0.5, adaptive steps up
to 1e-2 s (``impulse_tol`` = 5e-3 N s).
"""

import math
from dataclasses import dataclass, replace

import numpy as np

from ballenv.physics import Ground, Ring, Scene
from ballenv.physics.base.ring import inflated_radius

CONTACTS = ("mass_modification", "predictor_corrector")
INTEGRATORS = ("backward_euler", "generalized_alpha")


@dataclass(frozen=True)
class Case:
    """A hard case: ``simulate(scene, t_end, x0=x0, v0=v0)``."""

    name: str
    scene: Scene
    t_end: float
    x0: np.ndarray | None = None
    v0: np.ndarray | None = None

    def variant(self, contact, integrator):
        """The same case with another contact method and integrator."""
        return replace(self, scene=replace(self.scene, contact=contact, integrator=integrator))


def ring(**kw):
    base = dict(radius=0.1, n_nodes=32, youngs_modulus=10e6, thickness=2e-3, width=0.02, density=1100.0)
    base.update(kw)
    return Ring(**base)


def scene(rings, grounds=None, **kw):
    base = dict(dt=1e-2, adaptive=True, impulse_tol=5e-3)
    base.update(kw)
    return Scene(rings=rings, grounds=[Ground(friction=0.5)] if grounds is None else grounds, **base)


def safe_pressure(youngs_modulus, thickness, radius=0.1, fraction=0.2, cap=30e3):
    """A gauge pressure (Pa) at ``fraction`` of the wall's 100 % strain bound ``E h / (2 R)``."""
    return min(cap, fraction * 0.5 * youngs_modulus * thickness / radius)


def drop(name, height=0.5, t_end=0.6, scene_kw=None, **ring_kw):
    """A ring released at rest with its centre at ``height`` (m) above flat ground."""
    r = ring(position=(0.0, height), **ring_kw)
    return Case(name, scene([r], **(scene_kw or {})), t_end)


def on_slope(name, angle_deg, friction, t_end=0.5):
    """A ring released 5 cm above a slope of ``angle_deg`` through the origin."""
    a = math.radians(angle_deg)
    r = ring(pressure=30e3)
    lift = inflated_radius(r) + 0.05
    r = replace(r, position=(-math.sin(a) * lift, math.cos(a) * lift))
    return Case(name, scene([r], [Ground(angle=a, friction=friction)]), t_end)


def flat_ring(n_nodes=32, gap_ratio=0.1, radius=0.1):
    """Nodes (N, 2) of a ring of rest radius ``radius`` squashed nearly flat: a stadium of the rest
    perimeter whose flat walls are ``gap_ratio`` R apart (end caps of radius gap_ratio R / 2), nodes
    equally spaced along it, counter-clockwise, the bottom wall 0.1 mm above y = 0."""
    perimeter = 2 * math.pi * radius
    cap = 0.5 * gap_ratio * radius
    flat = 0.5 * (perimeter - 2 * math.pi * cap)
    s = (np.arange(n_nodes) + 0.5) * perimeter / n_nodes  # arc length from the bottom wall's left end
    x = np.empty((n_nodes, 2))
    for k, sk in enumerate(s):
        if sk < flat:  # bottom wall, left to right
            x[k] = (-0.5 * flat + sk, 0.0)
        elif sk < flat + math.pi * cap:  # right cap
            phi = (sk - flat) / cap - 0.5 * math.pi
            x[k] = (0.5 * flat + cap * math.cos(phi), cap + cap * math.sin(phi))
        elif sk < 2 * flat + math.pi * cap:  # top wall, right to left
            x[k] = (0.5 * flat - (sk - flat - math.pi * cap), 2 * cap)
        else:  # left cap
            phi = (sk - 2 * flat - math.pi * cap) / cap + 0.5 * math.pi
            x[k] = (-0.5 * flat + cap * math.cos(phi), cap + cap * math.sin(phi))
    x[:, 1] += 1e-4
    return x


def squashed_flat(name, gap_ratio=0.1, t_end=0.3, pressure=30e3):
    """A ring squashed nearly flat (:func:`flat_ring`, walls 0.1 R apart: 1 cm on a 20 cm ball) and
    held in a press: floor and ceiling (friction 0.5) 0.1 mm from its walls. Its gas (30 kPa at
    rest) is squeezed to about a tenth of its area, 1.7 MPa gauge, and pushes on both plates; the
    caps, bent to a radius of 5 mm (a quarter of an edge), spring out sideways."""
    r = ring(pressure=pressure)
    x = flat_ring(r.n_nodes, gap_ratio, r.radius)
    grounds = [Ground(friction=0.5), Ground(angle=math.pi, height=x[:, 1].max() + 1e-4, friction=0.5)]
    return Case(name, scene([r], grounds), t_end, x0=x, v0=np.zeros_like(x))


def released_flat(name, gap_ratio=0.1, t_end=0.3, pressure=30e3):
    """The ring of :func:`flat_ring` released on the floor, without the press."""
    r = ring(pressure=pressure)
    x = flat_ring(r.n_nodes, gap_ratio, r.radius)
    return Case(name, scene([r]), t_end, x0=x, v0=np.zeros_like(x))


def two_balls(name, speed=20.0, t_end=0.1):
    """Two rings resting on the ground, 2 cm apart, each moving at ``speed`` (m/s) toward the other."""
    r = ring(pressure=30e3)
    lift = inflated_radius(r) + 1e-3
    gap = 0.02
    a = replace(r, position=(-lift - 0.5 * gap, lift), velocity=(speed, 0.0))
    b = replace(r, position=(lift + 0.5 * gap, lift), velocity=(-speed, 0.0))
    return Case(name, scene([a, b]), t_end)


def collapsed(name, load=50.0, t_end=0.6):
    """A ring pressed flat by a regulated external pressure (``Scene.gas_exponent`` 0) of ``load``
    times its buckling load ``p_cr = E h^3 / (4 R^3)`` (20 Pa here), dropped from 0.5 m: it buckles,
    its walls meet and rest on each other through the self-contact barrier."""
    r = ring(position=(0.0, 0.5))
    p_cr = r.youngs_modulus * r.thickness**3 / (4.0 * r.radius**3)
    return Case(name, scene([replace(r, pressure=-load * p_cr)], gas_exponent=0.0), t_end)


def hard_cases():
    """Every named hard case (mass-modification, generalized-alpha; see Case.variant)."""
    return [
        Case("impact_30_m_s", scene([ring(pressure=30e3, position=(0.0, 0.3), velocity=(0.0, -30.0))]), 0.06),
        drop("modulus_0.1_MPa", youngs_modulus=0.1e6, pressure=safe_pressure(0.1e6, 2e-3)),
        drop("modulus_1_GPa", youngs_modulus=1e9, pressure=30e3),
        drop("thickness_0.005_R", thickness=5e-4, pressure=safe_pressure(10e6, 5e-4)),
        drop("thickness_0.3_R", thickness=3e-2, pressure=30e3),
        drop("pressure_zero", pressure=0.0),
        drop("pressure_10_bar", youngs_modulus=100e6, thickness=4e-3, pressure=1e6),
        drop("nodes_8", n_nodes=8, pressure=30e3),
        drop("nodes_512", n_nodes=512, pressure=30e3, t_end=0.45),
        on_slope("slope_0_deg", 0.0, 0.5),
        on_slope("slope_75_deg", 75.0, 0.5),
        on_slope("friction_0", 30.0, 0.0),
        on_slope("friction_2", 30.0, 2.0),
        drop("fixed_step_0.01_s", height=1.0, t_end=1.5, scene_kw={"adaptive": False}, pressure=30e3),
        squashed_flat("squashed_flat"),
        two_balls("two_balls_20_m_s"),
        collapsed("collapsed_by_external_pressure"),
    ]
