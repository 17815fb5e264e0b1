"""The effects that act on a ring, one module each, and their registry.

**The contract of a force effect** (a module; see :mod:`.gravity` for the smallest one). Module
attributes:

* ``NAME``: its name in the list of effects a scene switches on (``build.scene_effects``);
  ``enabled(scene) -> bool`` (Python): does the scene ask for it. What a scene does not name costs
  one branch per force evaluation.
* ``ENERGY_PART``: its column of the energy table (``"gravity"``), or None for a force without a
  potential (damping); ``LOW_RANK``: how many low-rank Jacobian columns it may append (at most).
* ``PARAMETERS``: names of its own per-ring parameters (SI units), and ``parameters(scene, r) ->
  tuple of floats`` for ring index ``r`` (Python) if there are any. They land in its field of the
  per-ring record ``Model.effect_parameters[r]``; the effect sees them as ``p``. The built-in
  effects read named ``Model`` fields and declare none.

and four numba kernels (``@kernel`` of :mod:`ballenv.physics.base.jit`), for ring ``r`` with nodes ``x`` (N,
2) m and velocities ``v`` (N, 2) m/s:

* ``on(model, p, r) -> bool``: the effect acts on ring ``r`` (checked before every other kernel);
* ``force(model, p, r, x, v, f)``: add its force (N) into ``f`` (N, 2);
* ``jacobian(model, p, r, x, v, coef_x, coef_v, ws, rank) -> rank``: add ``coef_x dF/dx + coef_v
  dF/dv`` to the band matrix ``ws.band`` (node blocks placed by ``ws.pos``; see ``linalg``) and its
  low-rank part as columns ``rank, rank + 1, ...`` of ``ws.u``, ``ws.w`` (the matrix gets
  ``+ u w^T``); return the new rank;
* ``energy(model, p, r, x, v) -> float``: its potential (J), or 0.

``EFFECTS`` lists them in the order their forces are summed; :mod:`ballenv.physics.effects.assembly` derives
the ring's total force, Jacobian and energy parts from it when numba compiles. Adding a force is one new
module here and one line in ``EFFECTS``; another list runs with ``Simulation(scene, effects=...)``.

Ground contact (:mod:`ballenv.physics.ground.contact`: constrained rows and Coulomb friction in the
Newton system) and ring collision (:mod:`ballenv.physics.walls.impulses`: impulses between rings and
within a ring) act through constraints and impulses in the step rather than as forces;
``build.CONSTRAINTS`` names them among a scene's effects (``build.scene_effects``).
"""

from . import bending, damping, gas, gravity, stretching

EFFECTS = (stretching, bending, gas, gravity, damping)
