"""The incremental potential of an implicit step of a shell (implicit.py), compiled: the step's
fixed data, the kinematics of an end position, ``Phi``, its gradient and Newton's direction.

For a step of ``h`` (s) from ``x0``, ``v0``, ``a0`` (generalized-alpha's ``alpha_m``, ``alpha_f``,
``beta``, ``gamma``; backward Euler ``0, 0, 1, 1`` with ``a0 = 0``)::

    a1 = (x1 - x0 - h v0) / (beta h^2) - (1/2 - beta) / beta a0,   v1 = v0 + h ((1 - gamma) a0 + gamma a1)
    Phi(x1) = c_M / 2 sum_i m_i |x1_i - y_i|^2 + Pi(x_a) / c_x + B(x1) + D(x1)
              + c / (2 c_v) v_a^T (M - W W^T) v_a                                          (J)

``x_a = x0 + c_x (x1 - x0)``, ``v_a = (1 - alpha_f) v1 + alpha_f v0``,
``y = x0 + h v0 + h^2 ((1/2 - beta) - alpha_m beta / (1 - alpha_m)) a0``; ``Pi`` the skin, gas and
gravity (potential.py), ``B`` the grounds' and drums' barriers (ground.py, drum.py; against the
planes at the step's end, ``st.heights``), ``D`` friction (friction.py, drum_friction.py; on the slip
relative to ``st.slide`` and to the drums' turn; touch/drums.py: none without drums), the
damping's Rayleigh term (damping.py). Its Hessian (N/m) is
``c_M M + c_x K(x_a) + Hess (B + D) + c c_v (M - W W^T)``. The arrays are the records of
stepdata.py (``st`` a ``ShellStep``, ``sp`` a ``Start``, ``wk`` a ``Work``).
"""

import math

from ...physics.base.jit import kernel
from ...physics.step import integrator
from ..skin import damping, gas, potential
from ..skin.bending import bending_hessians
from ..solve import stepsolve
from ..solve.blocks import assemble_hinges
from ..touch import drums, friction, ground

BENDING_AGE = 8  # fresh assemblies that keep the hinges' matrices


@kernel
def begin(method, st, x0, v0, a0, h, sp):
    """Fills ``sp`` for a step of ``h`` (s) from ``(x0, v0, a0)``: the target ``y``, the normal
    forces at ``x0``, the damping's basis and the coefficients ``(h, c_M, c_x, c_v)``."""
    s = method.solver
    c_m, c_x, c_v, am = integrator.coefficients(s, h)
    ga = method.generalized_alpha
    shift = (0.5 - s.beta) - (am * s.beta / (1.0 - am) if ga else 0.0)
    for i in range(x0.shape[0]):
        for c in range(3):
            a = a0[i, c] if ga else 0.0
            sp.x0[i, c], sp.v0[i, c], sp.a0[i, c] = x0[i, c], v0[i, c], a
            sp.target[i, c] = x0[i, c] + h * v0[i, c] + h * h * shift * a
    ground.normal_forces(x0, st.normals, st.heights, st.dhat, st.kappa, sp.lam)
    drums.begin(st.drums, x0, st.dhat, st.kappa)
    if st.damping > 0.0:
        damping.rigid_basis(x0, st.problem.model.mass, sp.basis)
    sp.coef[0], sp.coef[1], sp.coef[2], sp.coef[3] = h, c_m, c_x, c_v


@kernel
def kinematics(method, sp, x1, a1, v1, va):
    """``a1``, ``v1`` and ``v_a`` (module doc) of the end positions ``x1``, into the arrays given."""
    s, h = method.solver, sp.coef[0]
    b, g, af = s.beta, s.gamma, s.alpha_f
    for i in range(x1.shape[0]):
        for c in range(3):
            a = (x1[i, c] - sp.x0[i, c] - h * sp.v0[i, c]) / (b * h * h) - (0.5 - b) / b * sp.a0[i, c]
            v = sp.v0[i, c] + h * ((1.0 - g) * sp.a0[i, c] + g * a)
            a1[i, c], v1[i, c], va[i, c] = a, v, (1.0 - af) * v + af * sp.v0[i, c]


@kernel
def _force_point(sp, x1, xa):
    c_x = sp.coef[2]
    for i in range(x1.shape[0]):
        for c in range(3):
            xa[i, c] = sp.x0[i, c] + c_x * (x1[i, c] - sp.x0[i, c])


@kernel
def incremental(method, st, sp, x1, wk):
    """Phi(x1) (J), inf where a vertex reaches a ground."""
    p, c_m, c_x, c_v = st.problem, sp.coef[1], sp.coef[2], sp.coef[3]
    mass = p.model.mass
    inertia = 0.0
    for i in range(x1.shape[0]):
        for c in range(3):
            inertia += mass[i] * (x1[i, c] - sp.target[i, c]) ** 2
    total = 0.5 * c_m * inertia + ground.barrier_energy(x1, st.normals, st.heights, st.dhat, st.kappa)
    total += drums.energy(st.drums, x1, st.dhat, st.kappa)
    if not math.isfinite(total):
        return total
    _force_point(sp, x1, wk.xa)
    total += potential.energy(p.model, p.ws, wk.xa, p.loads) / c_x
    e = st.slip_speed * sp.coef[0]
    total += friction.friction_energy(x1, sp.x0, st.normals, st.slide, sp.lam, st.mu, e, wk.u3)
    total += drums.friction_energy(st.drums, x1, sp.x0, e)
    if st.damping > 0.0:
        kinematics(method, sp, x1, wk.a1, wk.v1, wk.va)
        damping.deformation_rate(wk.va, mass, sp.basis, wk.rate)
        rayleigh = 0.0
        for i in range(x1.shape[0]):
            for c in range(3):
                rayleigh += wk.va[i, c] * wk.rate[i, c]
        total += st.damping / (2.0 * c_v) * rayleigh
    return total


@kernel
def contact_gradient(st, sp, x1, grad, blocks, u3):
    """Adds the barriers' and friction's gradient (N) and Hessian blocks (N/m) at ``x1``."""
    ground.add_barrier(x1, st.normals, st.heights, st.dhat, st.kappa, grad, blocks)
    e = st.slip_speed * sp.coef[0]
    friction.add_friction(x1, sp.x0, st.normals, st.slide, sp.lam, st.mu, e, grad, blocks, u3)
    drums.add_contact(st.drums, x1, sp.x0, st.dhat, st.kappa, e, grad, blocks)


@kernel
def incremental_gradient(method, st, sp, x1, wk, grad, blocks):
    """``grad Phi`` (N) into ``grad`` (V, 3) and the contact's Hessian blocks (N/m) into ``blocks``
    (V, 3, 3), at ``x1``; leaves ``dV/dx`` at ``x_a`` in the shell's workspace."""
    p, c_m = st.problem, sp.coef[1]
    _force_point(sp, x1, wk.xa)
    potential.gradient(p.model, p.ws, wk.xa, p.loads, grad)
    mass = p.model.mass
    for i in range(x1.shape[0]):
        for c in range(3):
            grad[i, c] += c_m * mass[i] * (x1[i, c] - sp.target[i, c])
    if st.damping > 0.0:
        kinematics(method, sp, x1, wk.a1, wk.v1, wk.va)
        damping.deformation_rate(wk.va, mass, sp.basis, wk.rate)
        for i in range(x1.shape[0]):
            for c in range(3):
                grad[i, c] += st.damping * wk.rate[i, c]
    blocks[:] = 0.0
    contact_gradient(st, sp, x1, grad, blocks, wk.u3)


@kernel
def direction(st, sp, x1, grad, blocks, wk, dx, fresh, rtol):
    """Newton's correction (m) into ``dx`` from the gradient and contact blocks at ``x1``, solved to
    a residual of ``rtol`` of the gradient (stepsolve.py). The skin's element matrices are those of
    ``x1`` if ``fresh``, else those assembled at an earlier iterate; the hinges' (bending, about
    1e-3 of the matrix's diagonal on the default ball at its steps) are kept for up to
    ``BENDING_AGE`` fresh assemblies (``wk.bending_age``; -1: none kept). The mass term, the gas's
    rank-one term and the contact blocks are always those of ``x1``. Returns the CG iterations, -1
    when the envelope solved it, -2 when its matrix was not positive definite."""
    c_x, s = newton_matrix(st, sp, x1, wk, fresh)
    for i in range(x1.shape[0]):
        for c in range(3):
            wk.rhs[i, c] = -grad[i, c]
    coefficients = (c_x, s, st.damping * sp.coef[3], rtol)
    iterations = stepsolve.solve(
        st.problem, st.owners, st.op, coefficients, blocks, wk.mass_term, sp.basis, wk.rhs, dx, wk.cg, fresh
    )
    if iterations < 0:
        wk.bending_age[0] = -1  # the envelope's fallback scaled the element matrices
    return iterations


@kernel
def newton_matrix(st, sp, x1, wk, fresh):
    """The terms of Newton's matrix at ``x1`` (:func:`direction`): the element matrices in the
    shell's workspace (new if ``fresh``), ``dV/dx`` and ``wk.mass_term``; returns ``(c_x, s)``
    (``s`` Pa/m^3 the gas's rank-one weight)."""
    p, c_m, c_x, c_v = st.problem, sp.coef[1], sp.coef[2], sp.coef[3]
    _force_point(sp, x1, wk.xa)
    if fresh:
        age = wk.bending_age
        if age[0] < 0 or age[0] >= BENDING_AGE:
            m = p.model
            bending_hessians(wk.xa, m.hinges, m.theta0, m.weight, m.kb, p.ws.scratch, p.ws.hinge_hess)
            assemble_hinges(st.op.pattern, p.ws.hinge_hess, st.op.hinge_values)
            age[0] = 0
        age[0] += 1
        s = c_x * potential.triangle_hessian(p.model, p.ws, wk.xa)
    else:
        s = c_x * gas.gas_stiffness(p.model, gas.volume(wk.xa, p.model.triangles))
        gas.volume_gradient(wk.xa, p.model.triangles, p.ws.dvol)
    for i in range(x1.shape[0]):
        wk.mass_term[i] = (c_m + st.damping * c_v) * p.model.mass[i]
    return c_x, s
