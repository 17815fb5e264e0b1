"""Compile a :class:`Scene` into the flat arrays the stepper works on (data flows one way).

``Model`` holds the physics (per-ring arrays of length R and scene scalars), ``Solver`` the numerical
method, ``Workspace`` the scratch arrays of one ring's Newton solve. All are NamedTuples of NumPy
arrays and scalars: numba compiles them as records, they pickle, and they hold nothing else.
"""

from typing import NamedTuple

import numpy as np

from . import ring as ring_geometry
from .linalg import BAND_COLUMNS, MAX_LOW_RANK, zigzag_positions
from .loads import DAMPING_CENTRE_OF_MASS, DAMPING_NONE, DAMPING_RIGID

METHOD_BACKWARD_EULER = 0
METHOD_GENERALIZED_ALPHA = 1


class Model(NamedTuple):
    node_mass: np.ndarray  # (R,) kg
    ea: np.ndarray  # (R,) N
    ei: np.ndarray  # (R,) N m^2
    rest_len: np.ndarray  # (R,) m
    rest_turn: np.ndarray  # (R,) rad
    width: np.ndarray  # (R,) m
    radius: np.ndarray  # (R,) m
    pressurised: np.ndarray  # (R,) bool
    gas_constant: np.ndarray  # (R,) Pa m^(2k)
    gas_exponent: float
    atmospheric_pressure: float  # Pa
    gravity: np.ndarray  # (2,) m/s^2
    use_gravity: bool
    damping: float  # 1/s
    damping_mode: int


class Solver(NamedTuple):
    method: int
    alpha_m: float
    alpha_f: float
    beta: float
    gamma: float
    newton_tol: float  # residual relative to the forces it balances
    newton_max_iter: int
    dt: float  # s
    dt_min: float  # s
    adaptive: bool
    growth: float


class Workspace(NamedTuple):
    pos: np.ndarray  # (N,) zig-zag position of each node
    band: np.ndarray  # (2N, BAND_COLUMNS)
    u: np.ndarray  # (2N, MAX_LOW_RANK)
    w: np.ndarray  # (2N, MAX_LOW_RANK)
    cap: np.ndarray  # (MAX_LOW_RANK, MAX_LOW_RANK)
    coef: np.ndarray  # (MAX_LOW_RANK,)
    res: np.ndarray  # (2N,)
    work: np.ndarray  # (2N, 1 + MAX_LOW_RANK)
    force: np.ndarray  # (N, 2)
    dx: np.ndarray  # (N, 2) displacement of the step, the Newton unknown
    xe: np.ndarray  # (N, 2)
    ve: np.ndarray  # (N, 2)


def generalized_alpha_parameters(rho_infinity):
    """Chung-Hulbert parameters ``(alpha_m, alpha_f, beta, gamma)`` for a spectral radius rho_inf.

    ``alpha_m = (2 rho - 1) / (rho + 1)``, ``alpha_f = rho / (rho + 1)``,
    ``gamma = 1/2 - alpha_m + alpha_f``, ``beta = (1 - alpha_m + alpha_f)^2 / 4``: second order,
    unconditionally stable, high-frequency damping set by ``rho`` (1: none).
    """
    r = float(rho_infinity)
    alpha_m = (2.0 * r - 1.0) / (r + 1.0)
    alpha_f = r / (r + 1.0)
    gamma = 0.5 - alpha_m + alpha_f
    beta = 0.25 * (1.0 - alpha_m + alpha_f) ** 2
    return alpha_m, alpha_f, beta, gamma


def build_model(scene):
    """Per-ring arrays and scene scalars of ``scene``."""
    rings = scene.rings
    n = rings[0].n_nodes
    p_atm = scene.atmospheric_pressure
    k = scene.gas_exponent
    area0 = np.array([ring_geometry.rest_area(r.radius, n) for r in rings])
    pressurised = np.array([r.pressure is not None for r in rings])
    gauge = np.array([0.0 if r.pressure is None else r.pressure for r in rings])
    if scene.damping == 0.0:
        mode = DAMPING_NONE
    elif scene.damping_mode == "rigid":
        mode = DAMPING_RIGID
    else:
        mode = DAMPING_CENTRE_OF_MASS
    gravity = np.array(scene.gravity_vector, dtype=float)
    return Model(
        node_mass=np.array([ring_geometry.node_mass(r) for r in rings]),
        ea=np.array([ring_geometry.stretching_stiffness(r) for r in rings]),
        ei=np.array([ring_geometry.bending_stiffness(r) for r in rings]),
        rest_len=np.array([ring_geometry.rest_edge_length(r.radius, n) for r in rings]),
        rest_turn=np.full(len(rings), ring_geometry.rest_turning_angle(n)),
        width=np.array([r.width for r in rings]),
        radius=np.array([r.radius for r in rings]),
        pressurised=pressurised,
        gas_constant=(gauge + p_atm) * area0**k,
        gas_exponent=float(k),
        atmospheric_pressure=float(p_atm),
        gravity=gravity,
        use_gravity=bool(np.any(gravity != 0.0)),
        damping=float(scene.damping),
        damping_mode=mode,
    )


def build_solver(scene):
    """Integrator coefficients and step control of ``scene``."""
    if scene.integrator == "backward_euler":
        method = METHOD_BACKWARD_EULER
        alpha_m = alpha_f = 0.0
        beta = gamma = 1.0
    else:
        method = METHOD_GENERALIZED_ALPHA
        alpha_m, alpha_f, beta, gamma = generalized_alpha_parameters(scene.rho_infinity)
    return Solver(
        method=method,
        alpha_m=alpha_m,
        alpha_f=alpha_f,
        beta=beta,
        gamma=gamma,
        newton_tol=float(scene.newton_tol),
        newton_max_iter=int(scene.newton_max_iter),
        dt=float(scene.dt),
        dt_min=float(scene.dt_min),
        adaptive=bool(scene.adaptive),
        growth=1.25,
    )


def build_workspace(n_nodes):
    """Scratch arrays for one ring's Newton solve, allocated once per simulation."""
    n2 = 2 * n_nodes
    return Workspace(
        pos=zigzag_positions(n_nodes),
        band=np.zeros((n2, BAND_COLUMNS)),
        u=np.zeros((n2, MAX_LOW_RANK)),
        w=np.zeros((n2, MAX_LOW_RANK)),
        cap=np.zeros((MAX_LOW_RANK, MAX_LOW_RANK)),
        coef=np.zeros(MAX_LOW_RANK),
        res=np.zeros(n2),
        work=np.zeros((n2, 1 + MAX_LOW_RANK)),
        force=np.zeros((n_nodes, 2)),
        dx=np.zeros((n_nodes, 2)),
        xe=np.zeros((n_nodes, 2)),
        ve=np.zeros((n_nodes, 2)),
    )
