"""The local error of a step in contact, which the error-controlled step (``Scene.rtol`` with
``Scene.contact_error = "doubling"``) keeps below tolerance where the smooth estimate of
:mod:`ballenv.physics.step.local_error` does not hold.

While a ring touches a ground (a node constrained at the step's start or end: in contact, arriving
or lifting off), its motion is not smooth: a node's arrival or release falls somewhere inside the
step and the reaction switches on or off there, so the error of the step is of lower order than the
integrator's. Three measures, each at most 1 within tolerance, cover it:

* arrival (:func:`arrival_norm`): an implicit step spreads the impulse that stops an arriving node
  over the whole step, as if the node had touched at its start; the ring's error from that grows
  with the distance ``d_i`` (m) the node still had to go at the step's start. The norm is
  ``sum_i d_i / (N (atol + rtol R))`` over the ring's arriving nodes (``N`` nodes, radius ``R``,
  m), ``O(h)``: a long flight step that ends on the ground is cut back near the first touch.
* step doubling (:func:`doubling_norm`): the step is taken again as two halves and the ring's rigid
  motion compared, whole step less halves::

      e_v = |ubar_h - ubar_h/2|           (m/s)  centre-of-mass velocity
      e_w = |L_h - L_h/2| / (M R)          (m/s)  angular momentum about the centre of mass
      e_x = RMS_i |x_i,h - x_i,h/2|        (m)    node positions

  with ``L = sum_i m (x_i - xbar) x v_i`` (kg m^2/s) and ``M`` the ring's mass (kg); the norm is
  ``max(e_v / (rtol sqrt(g R)), e_w / (rtol sqrt(g R)), e_x / (atol + rtol R))``, ``sqrt(g R)``
  (m/s) being the speed of a fall through the ring's radius, so ``rtol`` asks the same relative
  accuracy of the ring's momentum ``M sqrt(g R)`` (N s) as of its positions. The halves are the step
  taken (the more accurate of the two); the step-size factor is ``norm^(-1/2)`` (``O(h^2)`` where an
  arrival or release dominates, higher in smooth contact).
* the contact impulse (``step.stepper.contact_impulse``) at most ``LIFTOFF_IMPULSE sqrt(rtol) M sqrt(g R)``
  (N s, :func:`build.impulse_bounds`): a node is released at the start of the step whose end
  reaction pulls, in the whole step and in both halves alike, so doubling does not see a release a
  step early; this bound caps the impulse such a step can miss (``LIFTOFF_IMPULSE`` = 2, chosen on
  the six balls of ``benchmarks/ball_family.py`` with ``benchmarks/accuracy.py``). The default,
  ``contact_error = "impulse"``, bounds the contact impulse at ``rtol M sqrt(g R)`` instead and
  lands a step on each first touch (:mod:`ballenv.physics.ground.touchdown`).

A ring's rebound and spin follow from its rigid motion, not from the wall's vibration, whose
velocity field the doubling leaves out: a stiff ball's chattering contact would keep that error
above tolerance at any step.
"""

import math

from ..base.geometry import centre_of_mass
from ..base.jit import kernel
from ..ground.contact import FREE, frame

LIFTOFF_IMPULSE = 2.0  # contact impulse per step over sqrt(rtol) M sqrt(g R) under error control
SCALE_GRAVITY = 9.81  # m/s^2: the g of the speed scale sqrt(g R) in a scene without gravity


@kernel
def in_contact(state, trial):
    """A node of any ring is constrained at the step's start (``state``) or end (``trial``)."""
    for r in range(state.active.shape[0]):
        for i in range(state.active.shape[1]):
            if state.active[r, i] != FREE or trial.active[r, i] != FREE:
                return True
    return False


@kernel
def rigid_momentum(x, v):
    """``(xbar, ybar, ubar, vbar, l)``: the centre of mass (m), its velocity (m/s) and the angular
    momentum about it per node mass (m^2/s) of nodes at ``x`` moving with ``v`` ((N, 2))."""
    cx, cy, ux, uy = centre_of_mass(x, v)
    spin = 0.0
    for i in range(x.shape[0]):
        spin += (x[i, 0] - cx) * (v[i, 1] - uy) - (x[i, 1] - cy) * (v[i, 0] - ux)
    return cx, cy, ux, uy, spin


@kernel
def doubling_norm(model, solver, r, whole, halves):
    """Ring ``r``'s scaled contact error from its state after the whole step (``whole``) and after
    two half steps (``halves``; States): at most 1 is within tolerance."""
    n = whole.x.shape[1]
    _, _, ux0, uy0, l0 = rigid_momentum(whole.x[r], whole.v[r])
    _, _, ux1, uy1, l1 = rigid_momentum(halves.x[r], halves.v[r])
    radius = model.radius[r]
    g = math.hypot(model.gravity[0], model.gravity[1])
    speed = solver.rtol * math.sqrt((g if g > 0.0 else SCALE_GRAVITY) * radius)  # m/s
    e_v = math.hypot(ux1 - ux0, uy1 - uy0) / speed
    e_w = abs(l1 - l0) / (n * radius) / speed
    total = 0.0
    for i in range(n):
        dx = halves.x[r, i, 0] - whole.x[r, i, 0]
        dy = halves.x[r, i, 1] - whole.x[r, i, 1]
        total += dx * dx + dy * dy
    e_x = math.sqrt(total / n) / (solver.atol + solver.rtol * radius)
    return max(e_v, e_w, e_x)


@kernel
def arrival_norm(model, solver, r, state, trial, surface_start):
    """Ring ``r``'s scaled arrival error of the step ``state -> trial``: the distance its arriving
    nodes (free at the start, constrained at the end) had to their ground at the step's start
    (``surface_start``: the grounds then, rows ``base.layout.SURFACE``), summed and divided by the node
    count, over ``atol + rtol R``: at most 1 is within tolerance."""
    n = state.x.shape[1]
    total = 0.0
    for i in range(n):
        g = trial.active[r, i]
        if state.active[r, i] != FREE or g == FREE:
            continue
        _, _, gap = frame(surface_start, g, state.x[r, i, 0], state.x[r, i, 1])
        total += max(0.0, gap)
    return total / n / (solver.atol + solver.rtol * model.radius[r])
