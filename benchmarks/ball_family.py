"""The balls of the accuracy study: six rings that differ in what dominates them, each dropped onto
its ground, and their converged references.

=============  ======  ======  =======  ======  =======  =========  =========  ====================
ball           R (m)   h (mm)  E (MPa)  b (cm)  p (kPa)  mass (g)   p R^3/EI   ground
=============  ======  ======  =======  ======  =======  =========  =========  ====================
bending        0.10    2       10       0.209   1        2.9        150        flat, frictionless
stiff          0.10    4       200      1       2        28         1.9        flat, friction 0.5
tennis         0.033   3.3     5        6       80       45         190        flat, friction 0.5
basketball     0.12    3       20       20      55       500        2,100      flat, friction 0.5
light          0.05    1       2        1       5        3.5        3,800      flat, frictionless
env            0.12    2       10       2       30       33         7,800      30 deg slope, none
=============  ======  ======  =======  ======  =======  =========  =========  ====================

``p R^3 / EI`` is the gas's stiffness against the wall's bending (``EI = E b h^3 / 12`` per ring,
``p`` per unit width): for the ring's mode ``n`` the ratio of the two is about this over ``n^2``.
All: density 1100 kg/m^3, N = 64 nodes, centre released at rest at 1 m (0.5 m above the slope's
surface for ``env``), gas law ``p A = const`` over an absolute pressure (``bending``: p_atm = 0,
the scene of the peer benchmark; the others 101,325 Pa), no damping, until ``T_END`` (past the first apex).
(With friction on the slope, fixed small steps stop with "the step gained energy" during the
rolling contact; a known limit of today's contact, so the slope here is frictionless.)

The reference of a ball is a generalized-alpha run (``rho_infinity`` = 0.9, steps <= 1 ms) whose
step follows the contact impulse alone (``Scene.impulse_tol``) at ``REFERENCE_TOL`` times the ring's
momentum scale ``M sqrt(g R)`` (N s): in contact its steps are 0.04-0.3 us, in flight the centre of
mass is ballistic whatever the step. Its own error is estimated against the run at twice that
tolerance (:func:`reference_apex`): 2e-6 to 1.2e-4 over the six balls. Fixed steps converge at
first order in contact (each node's arrival and lift-off falls inside a step): at 5 us the
fixed-step first apex of the tennis ball still moved by 1e-3 when the step was halved and lay
3.4e-4 below the converged one, the stiff ball's 5e-4 above it.
"""

import dataclasses
import math

from ballenv.physics import Ground, Ring, Scene, simulate
from ballenv.physics.base.ring import total_mass

T_END = {"env": 0.8}  # s, default 1 s: past the first apex
REFERENCE_TOL = 5e-5  # the reference's contact impulse per step over M sqrt(g R)
REFERENCE_DT = 1e-3  # s: the reference's largest step
SLOPE = math.radians(30.0)

# name -> (radius, thickness, youngs_modulus, width, pressure, friction, slope, p_atm)
BALLS = {
    "bending": (0.10, 2e-3, 10e6, 2.09e-3, 1e3, 0.0, False, 0.0),
    "stiff": (0.10, 4e-3, 200e6, 0.01, 2e3, 0.5, False, 101325.0),
    "tennis": (0.033, 3.3e-3, 5e6, 0.06, 80e3, 0.5, False, 101325.0),
    "basketball": (0.12, 3e-3, 20e6, 0.20, 55e3, 0.5, False, 101325.0),
    "light": (0.05, 1e-3, 2e6, 0.01, 5e3, 0.0, False, 101325.0),
    "env": (0.12, 2e-3, 10e6, 0.02, 30e3, 0.0, True, 101325.0),
}


def ball_scene(name, n_nodes=64, **numerics):
    """Ball ``name`` of :data:`BALLS` on its ground, with ``numerics`` (Scene keywords)."""
    radius, thickness, modulus, width, pressure, friction, slope, p_atm = BALLS[name]
    position = (0.0, 1.0)
    ground = Ground(friction=friction)
    if slope:
        ground = Ground(angle=SLOPE, friction=friction)
        position = (0.0, 0.5 / math.cos(SLOPE))  # 0.5 m from the slope's surface, along its normal
    ring = Ring(
        radius=radius, n_nodes=n_nodes, youngs_modulus=modulus, thickness=thickness, width=width,
        density=1100.0, pressure=pressure, position=position,
    )  # fmt: skip
    return Scene(rings=[ring], grounds=[ground], atmospheric_pressure=p_atm, **numerics)


def gas_to_bending(name):
    """``p R^3 / EI = 12 p R^3 / (E h^3)`` of ball ``name`` (dimensionless)."""
    radius, thickness, modulus, _, pressure, *_ = BALLS[name]
    return 12.0 * pressure * radius**3 / (modulus * thickness**3)


def first_apex(name, scene):
    """(first-apex height of the centre of mass (m), trajectory) of ``scene`` (ball ``name``); NaN
    without apex."""
    traj = simulate(scene, t_end=T_END.get(name, 1.0))
    apexes = traj.apexes()
    return (float(apexes[0, 1]) if len(apexes) else math.nan), traj


def momentum_scale(name):
    """``M sqrt(g R)`` (N s) of ball ``name``: its mass times the speed of a fall through its radius."""
    ring = ball_scene(name).rings[0]
    return total_mass(ring) * math.sqrt(9.81 * ring.radius)


def reference_scene(name, tol=REFERENCE_TOL, n_nodes=64):
    """Ball ``name`` of ``n_nodes`` nodes with the reference's step control: contact impulse per step
    at most ``tol M sqrt(g R)`` (N s, error control off), steps <= ``REFERENCE_DT``."""
    impulse_tol = tol * momentum_scale(name)
    return ball_scene(
        name, n_nodes, adaptive=True, dt=REFERENCE_DT, rtol=0.0, impulse_tol=impulse_tol, rho_infinity=0.9
    )


def reference_apex(name, tol=REFERENCE_TOL, n_nodes=64):
    """(converged first apex (m), its relative change at twice ``tol``) of ball ``name`` at ``n_nodes``
    nodes."""
    fine = first_apex(name, reference_scene(name, tol, n_nodes))[0]
    coarse = first_apex(name, reference_scene(name, 2.0 * tol, n_nodes))[0]
    return fine, abs(coarse - fine) / fine


def with_numerics(scene, **numerics):
    """``scene`` with other Scene keywords."""
    return dataclasses.replace(scene, **numerics)
