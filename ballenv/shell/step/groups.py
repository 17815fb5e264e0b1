"""Which shells step together: shells that may touch in a step take one joint step (joint.py),
the others step alone (implicit.py), exactly as without contact.

For a step of ``h`` (s) from ``x0``, ``v0``, ``a0`` each shell has a bounding sphere about the
mean of its vertices ``c`` (m) of radius ``r = max_i |x0_i - c|`` and a predicted reach
``m = max_i |h v0_i + h^2 a0_i / 2|`` (m, its predictor's largest motion). Two shells are grouped
(transitively) when ``|c_a - c_b| <= r_a + r_b + PREDICTION_MARGIN (m_a + m_b) + dhat``. Shells
stepped apart are then checked: the sphere about ``c`` that holds both ends ``x0`` and ``x1`` of
each (so every straight motion between them) must stay more than ``dhat`` from every other such
sphere; otherwise the step is taken again with their groups merged. So a pair of shells within
the barrier's reach is never stepped apart, and a scene whose shells never come close pays the
spheres' test only. With ``Scene.self_contact`` every shell steps in a group (its own pairs).
"""

import numpy as np
from numpy.typing import NDArray

from . import implicit, joint
from .jointdata import Joint, make_joint
from .stepdata import ShellStep

F64 = NDArray[np.float64]
PREDICTION_MARGIN = 2.0  # the predictor's motion times this bounds a step's motion in the grouping
ROOM_GROWTH = 4  # pair records grow by this factor when they do not fit, at most ROOM_TRIES times
ROOM_TRIES = 4


def _merge(groups: list[list[int]], a: int, b: int) -> list[list[int]]:
    """``groups`` with the groups of shells ``a`` and ``b`` made one."""
    ga = next(g for g in groups if a in g)
    gb = next(g for g in groups if b in g)
    if ga is gb:
        return groups
    return [g for g in groups if g is not ga and g is not gb] + [sorted(ga + gb)]


def spheres(x: F64) -> tuple[F64, F64]:
    """Each shell's centre (S, 3) m and radius (S,) m of ``x`` (S, V, 3)."""
    c = x.mean(axis=1)
    return c, np.linalg.norm(x - c[:, None, :], axis=2).max(axis=1)


class Contacts:
    """The grouping and the joint steps' records (one per group met) of a run."""

    def __init__(self, steps: list[ShellStep], dhat: float, self_contact: bool) -> None:
        self.steps, self.dhat, self.self_contact = steps, dhat, self_contact
        self.kappa = np.array([st.kappa for st in steps], dtype=np.float64)
        self.joints: dict[tuple[int, ...], tuple[Joint, int]] = {}
        self.last_groups: list[list[int]] = []  # the groups of the last step returned

    def predict(self, x: F64, v: F64, a: F64, h: float) -> list[list[int]]:
        """The groups of the module doc for a step of ``h`` (s)."""
        groups = [[k] for k in range(len(x))]
        c, r = spheres(x)
        reach = np.linalg.norm(h * v + 0.5 * h * h * a, axis=2).max(axis=1)
        for i in range(len(x)):
            for j in range(i + 1, len(x)):
                gap = np.linalg.norm(c[i] - c[j]) - r[i] - r[j]
                if gap <= PREDICTION_MARGIN * (reach[i] + reach[j]) + self.dhat:
                    groups = _merge(groups, i, j)
        return groups

    def conflicts(self, groups: list[list[int]], x0: F64, x1: F64) -> list[tuple[int, int]]:
        """Pairs of shells of different groups whose swept spheres come within ``dhat``."""
        c, r0 = spheres(x0)
        r = np.maximum(r0, np.linalg.norm(x1 - c[:, None, :], axis=2).max(axis=1))
        label = {k: n for n, g in enumerate(groups) for k in g}
        out = []
        for i in range(len(x0)):
            for j in range(i + 1, len(x0)):
                if label[i] != label[j] and np.linalg.norm(c[i] - c[j]) <= r[i] + r[j] + self.dhat:
                    out.append((i, j))
        return out

    def _joint(self, group: tuple[int, ...], room: int) -> Joint:
        kept = self.joints.get(group)
        if kept is None or kept[1] < room:
            model = self.steps[group[0]].problem.model
            rest = np.array([self.steps[k].problem.model.rest for k in group])
            mesh = (model.triangles, model.edges)
            jt = make_joint(mesh, rest, self.kappa[list(group)], self.dhat, self.self_contact, room)
            kept = self.joints[group] = (jt, room)
        return kept[0]

    def step_group(
        self, method: implicit.Integrator, group: list[int], state: tuple[F64, F64, F64], h: float
    ) -> list[implicit.StepResult]:
        """The step of one group: alone (implicit.step) or joint (joint.step)."""
        x, v, a = state
        if len(group) == 1 and not self.self_contact:
            k = group[0]
            return [implicit.step(method, self.steps[k], x[k], v[k], a[k], h)]
        key, room = tuple(group), self.joints.get(tuple(group), (None, 1))[1]
        sts = tuple(self.steps[k] for k in group)
        x0, v0, a0 = (np.ascontiguousarray(s[list(group)]) for s in state)
        for _ in range(ROOM_TRIES):
            try:
                return joint.step(method, sts, self._joint(key, room), x0, v0, a0, h)
            except joint.PairsOverflow:
                room *= ROOM_GROWTH
        raise implicit.StepFailure(joint.FAILURES[5])

    def step(
        self, method: implicit.Integrator, state: tuple[F64, F64, F64], h: float
    ) -> list[implicit.StepResult]:
        """Every shell's step of ``h`` (s), or :class:`implicit.StepFailure`."""
        x, v, a = state
        groups = self.predict(x, v, a, h)
        while True:
            results: list[implicit.StepResult | None] = [None] * len(x)
            for g in groups:
                for k, res in zip(g, self.step_group(method, g, state, h), strict=True):
                    results[k] = res
            done = [res for res in results if res is not None]
            clashes = self.conflicts(groups, x, np.array([res.x for res in done]))
            if not clashes:
                self.last_groups = groups
                return done
            for i, j in clashes:
                groups = _merge(groups, i, j)
