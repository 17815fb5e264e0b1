"""What an implicit step asks of a shell's drums (``ShellStep.drums``: a ``drum.Drums`` record, or
None when the scene has none), compiled into the step only for a scene with drums.

Each function here is resolved by numba from the type of ``drums``: with a ``Drums`` record it
calls drum.py's barrier and collision bound and drum_friction.py's friction; with None it is a
constant (no energy, no force, no limit on the step, nothing frictional), so the step of a scene
without drums compiles none of their code and computes exactly what it did before drums existed.
Python calls drum.py and drum_friction.py directly.
"""

from numba import types
from numba.extending import overload

from ...physics.base.jit import copy_into
from . import drum, drum_friction


def _without(drums: object) -> bool:
    return isinstance(drums, types.NoneType)


def begin(drums, x0, dhat, kappa):
    """The normal forces (N) at the step's start ``x0`` into ``drums.lam`` (held through the step)."""


def energy(drums, x, dhat, kappa):
    """The drums' barrier energy (J) at ``x``."""


def friction_energy(drums, x, x0, e):
    """The drums' friction potential (J) at ``x`` for the step from ``x0`` (``e = eps_v h``, m)."""


def add_contact(drums, x, x0, dhat, kappa, e, grad, blocks):
    """Adds the drums' barrier and friction gradient (N) and Hessian blocks (N/m, positive part)."""


def max_step(drums, x, dx):
    """The largest ``alpha <= 1`` for which ``x + alpha dx`` stays off the drums (drum.max_step)."""


def lag_change(drums, x, dhat, kappa):
    """The normal forces at ``x`` into ``drums.lam_new``; the largest change (N) from ``drums.lam``."""


def accept_lag(drums):
    """Takes ``drums.lam_new`` as the lagged normal forces."""


def frictional(drums):
    """A drum has friction."""


@overload(begin, inline="always")
def _begin(drums, x0, dhat, kappa):
    if _without(drums):
        return lambda drums, x0, dhat, kappa: None
    return lambda drums, x0, dhat, kappa: drum.normal_forces(x0, drums, dhat, kappa, drums.lam)


@overload(energy, inline="always")
def _energy(drums, x, dhat, kappa):
    if _without(drums):
        return lambda drums, x, dhat, kappa: 0.0
    return lambda drums, x, dhat, kappa: drum.barrier_energy(x, drums, dhat, kappa)


@overload(friction_energy, inline="always")
def _friction_energy(drums, x, x0, e):
    if _without(drums):
        return lambda drums, x, x0, e: 0.0
    return lambda drums, x, x0, e: drum_friction.friction_energy(x, x0, drums, e)


@overload(add_contact, inline="always")
def _add_contact(drums, x, x0, dhat, kappa, e, grad, blocks):
    if _without(drums):
        return lambda drums, x, x0, dhat, kappa, e, grad, blocks: None

    def impl(drums, x, x0, dhat, kappa, e, grad, blocks):
        drum.add_barrier(x, drums, dhat, kappa, grad, blocks, True)
        drum_friction.add_friction(x, x0, drums, e, grad, blocks)

    return impl


@overload(max_step, inline="always")
def _max_step(drums, x, dx):
    if _without(drums):
        return lambda drums, x, dx: 1.0
    return lambda drums, x, dx: drum.max_step(x, dx, drums)


@overload(lag_change, inline="always")
def _lag_change(drums, x, dhat, kappa):
    if _without(drums):
        return lambda drums, x, dhat, kappa: 0.0

    def impl(drums, x, dhat, kappa):
        drum.normal_forces(x, drums, dhat, kappa, drums.lam_new)
        change = 0.0
        for i in range(drums.lam.shape[0]):
            for k in range(drums.lam.shape[1]):
                change = max(change, abs(drums.lam_new[i, k] - drums.lam[i, k]))
        return change

    return impl


@overload(accept_lag, inline="always")
def _accept_lag(drums):
    if _without(drums):
        return lambda drums: None
    return lambda drums: copy_into(drums.lam, drums.lam_new)


@overload(frictional, inline="always")
def _frictional(drums):
    if _without(drums):
        return lambda drums: False

    def impl(drums):
        for k in range(drums.mu.shape[0]):
            if drums.mu[k] > 0.0:
                return True
        return False

    return impl
