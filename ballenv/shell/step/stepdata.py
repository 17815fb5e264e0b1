"""The records an implicit step of a shell reads and writes (SI units), built once per run:
``ShellStep`` (the shell's model, its grounds and drums, contact and damping constants, the linear
solve's operator), ``Start`` (a step's data fixed at its start) and ``Work`` (the step's scratch), so that
the compiled step (implicit.py) allocates nothing."""

from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from ..rest.equilibrium import Problem
from ..skin.model import ShellModel, build_workspace
from ..solve import cg, envelope, stepsolve
from ..solve.blocks import block_pattern
from ..touch.drum import Drums

F64 = NDArray[np.float64]


class Start(NamedTuple):
    """A step's data fixed at its start."""

    x0: F64  # (V, 3) m
    v0: F64  # (V, 3) m/s
    a0: F64  # (V, 3) m/s^2, zero for backward Euler
    target: F64  # (V, 3) m: y of the incremental potential
    lam: F64  # (V, G) N, lagged normal forces
    basis: F64  # (6, V, 3) damping's W at x0, or (0, V, 3) without damping
    coef: F64  # (4,): h s, c_M 1/s^2, c_x, c_v 1/s


class Work(NamedTuple):
    """A step's scratch and its results (x1, v1, a1, contact force)."""

    x: F64  # (V, 3) m: Newton's iterate, then the step's end
    v1: F64  # (V, 3) m/s
    a1: F64  # (V, 3) m/s^2
    va: F64  # (V, 3) m/s
    xa: F64  # (V, 3) m: where the shell's forces are taken
    rate: F64  # (V, 3) kg m/s: damping.deformation_rate
    grad: F64  # (V, 3) N
    blocks: F64  # (V, 3, 3) N/m: the grounds' and friction's Hessian blocks
    trial_grad: F64  # (V, 3) N
    trial_blocks: F64  # (V, 3, 3) N/m
    dx: F64  # (V, 3) m
    rhs: F64  # (V, 3) N
    trial: F64  # (V, 3) m
    force: F64  # (V, 3) N: the contact force at the step's end
    lam: F64  # (V, G) N
    cg: F64  # (4, V, 3) CG's scratch
    mass_term: F64  # (V,) N/m: the Newton matrix's diagonal per vertex
    bending_age: NDArray[np.int64]  # (1,): fresh assemblies since the hinges' matrices, -1: none
    u3: F64  # (3,)
    energy: F64  # (1,) J: the total energy at the step's end (implicit.total_energy)
    vertex_grad: F64  # (1, 3) N: a contact vertex's barriers' and friction's gradient (relax.py)
    vertex_hess: F64  # (1, 3, 3) N/m: their Hessian
    vertex_block: F64  # (3, 3) N/m: the rest of its block of Newton's matrix


class ShellStep(NamedTuple):
    """What the steps of one shell read (SI units), with its step's records."""

    problem: Problem  # loads: gravity m_i g (N)
    gravity: float  # |g| m/s^2
    normals: F64  # (G, 3) grounds' unit normals
    heights: F64  # (G,) m: the planes' offsets at the step's end (touch/motion.py)
    mu: F64  # (G,) friction coefficients
    slide: F64  # (G, 3) m: the grounds' surfaces' slide over the step (touch/motion.py)
    dhat: float  # m
    kappa: float  # N/m
    slip_speed: float  # eps_v m/s
    damping: float  # c 1/s
    owners: stepsolve.Owners  # stepsolve.block_owners
    radius: float  # m
    op: cg.Operator  # the Newton system's operator (stepsolve.py)
    start: Start
    work: Work
    drums: Drums | None = None  # the drums (touch/drum.py), None without: no drum code is compiled


def make_start(n_vertices: int, n_grounds: int, damped: bool) -> Start:
    """A zero ``Start`` for a shell of ``n_vertices`` over ``n_grounds`` grounds."""
    z = np.zeros
    v3 = (n_vertices, 3)
    return Start(z(v3), z(v3), z(v3), z(v3), z((n_vertices, n_grounds)), z((6 if damped else 0,) + v3), z(4))


def make_work(n_vertices: int, n_grounds: int) -> Work:
    """A zero ``Work`` for a shell of ``n_vertices`` over ``n_grounds`` grounds."""
    z = np.zeros
    v3, b3 = (n_vertices, 3), (n_vertices, 3, 3)
    return Work(
        z(v3), z(v3), z(v3), z(v3), z(v3), z(v3),
        z(v3), z(b3), z(v3), z(b3), z(v3), z(v3), z(v3), z(v3), z((n_vertices, n_grounds)),
        z((4,) + v3), z(n_vertices), np.full(1, -1, dtype=np.int64), z(3), z(1),
        z((1, 3)), z((1, 3, 3)), z((3, 3)),
    )  # fmt: skip


def make_step(
    model: ShellModel,
    gravity: F64,
    grounds: tuple[F64, F64, F64, F64],
    contact: tuple[float, float, float],
    c: float,
    drums: Drums | None = None,
) -> ShellStep:
    """The step data of ``model`` under ``gravity`` (3,) m/s^2, ``grounds`` (normals, heights, mu, slide),
    ``contact`` (dhat m, kappa N/m, eps_v m/s), damping ``c`` (1/s) and ``drums`` (or None)."""
    n, n_grounds = len(model.rest), len(grounds[1])
    loads = model.mass[:, None] * gravity[None, :]
    env = envelope.build_envelope(n, model.triangles, model.hinges)
    free = np.ones(model.rest.shape, dtype=np.bool_)
    problem = Problem(model, build_workspace(model), env, loads, free)
    owners = stepsolve.block_owners(model.triangles, n)
    radius = float(np.linalg.norm(model.rest, axis=1).max())
    op = cg.make_operator(block_pattern(n, model.triangles, model.hinges), stepsolve.RANK)
    start, work = make_start(n, n_grounds, c > 0.0), make_work(n, n_grounds)
    return ShellStep(
        problem, float(np.linalg.norm(gravity)), *grounds, *contact, c, owners, radius, op, start, work, drums
    )
