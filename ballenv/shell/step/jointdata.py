"""The records of a joint step of a group of shells that may touch (joint.py), built once per group
and run (SI units), so that the compiled step allocates nothing.

The group's ``S`` shells share one mesh of ``V`` vertices; its arrays hold every shell's vertices,
(S, V, 3), seen by the contact kernels as (S V, 3) with vertex ``k V + i`` of shell ``k``
(broadphase.py). Each shell keeps its own ``ShellStep`` (stepdata.py) for its own terms.
"""

from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from ..touch.broadphase import Candidates, make_candidates
from ..touch.distance import PairScratch, make_scratch

F64 = NDArray[np.float64]
PAIRS_PER_VERTEX = 8  # room for candidate pairs at the start (grown when they do not fit, groups.py)
TOUCHING_PER_VERTEX = 2  # and for touching pairs' matrices


class Joint(NamedTuple):
    """A group's joint step: Newton's iterate and scratch, and its contact pairs."""

    x: F64  # (S, V, 3) m: Newton's iterate, then the step's end
    dx: F64  # (S, V, 3) m
    trial: F64  # (S, V, 3) m
    grad: F64  # (S, V, 3) N
    blocks: F64  # (S, V, 3, 3) N/m: grounds', friction's and the pairs' diagonal blocks
    trial_grad: F64  # (S, V, 3) N
    trial_blocks: F64  # (S, V, 3, 3) N/m
    force: F64  # (S, V, 3) N: the contact force at the step's end
    rhs: F64  # (S, V, 3) N
    cg: F64  # (4, S, V, 3) the joint CG's scratch
    rest: F64  # (S V, 3) m: the shells' rest positions (the edge-edge mollifier)
    kappa: F64  # (S,) N/m: each shell's barrier stiffness
    dhat: float  # m
    candidates: Candidates
    active: NDArray[np.int64]  # (A, 4): the touching pairs' vertices
    hess: F64  # (A, 12, 12) N/m: their projected barrier Hessians
    n_active: NDArray[np.int64]  # (1,)
    scratch: PairScratch
    box: F64  # (2, 3) m


def make_joint(
    mesh: tuple[NDArray[np.int64], NDArray[np.int64]],
    rest: F64,
    kappa: F64,
    dhat: float,
    self_contact: bool,
    room: int = 1,
) -> Joint:
    """The records of a group of ``len(kappa)`` shells of the mesh ``(triangles, edges)``, at rest
    at ``rest`` (S, V, 3) m, with ``room`` times the starting room for pairs."""
    s, n_vertices = len(kappa), rest.shape[1]
    triangles, edges = mesh
    z = np.zeros
    v3, b3 = (s, n_vertices, 3), (s, n_vertices, 3, 3)
    pairs = room * PAIRS_PER_VERTEX * s * n_vertices
    touching = room * TOUCHING_PER_VERTEX * s * n_vertices
    return Joint(
        z(v3), z(v3), z(v3), z(v3), z(b3), z(v3), z(b3), z(v3), z(v3), z((4,) + v3),
        np.ascontiguousarray(rest.reshape(-1, 3), dtype=np.float64), np.asarray(kappa, dtype=np.float64),
        float(dhat), make_candidates(triangles, edges, s, pairs, self_contact),
        z((touching, 4), dtype=np.int64), z((touching, 12, 12)), z(1, dtype=np.int64), make_scratch(),
        z((2, 3)),
    )  # fmt: skip
