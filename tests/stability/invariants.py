"""What every hard case must show, measured on a run: finite accepted states, no penetration of a
ground or of another ring beyond the tolerance, no growth of mechanical plus gas energy beyond what
the collision impulses' push-out created (reported), and either t_end reached or a documented
:class:`SimulationError`.

Used by the stability tests and by ``benchmarks/soak.py``.
"""

from dataclasses import dataclass, field

import numpy as np

from ballenv.physics import simulate
from ballenv.physics.build import build_collision_workspace
from ballenv.physics.ground.motion import ground_array
from ballenv.physics.simulation import SimulationError
from ballenv.physics.walls.impulses import find_contacts

GROUND_TOLERANCE = 1e-6  # m: deepest a node may be below a ground in an accepted state
ENERGY_ROUND_OFF = 1e-9  # energy growth allowed, relative to the sum of |energy parts| at the start
# documented SimulationError messages name the setting to change
DOCUMENTED_ERRORS = ("Scene.dt_min", "Scene.impulse_tol")


@dataclass
class Audit:
    """Invariants of one run.

    Attributes:
        reached_end: the run reached t_end.
        error: the SimulationError message, or "" if none.
        finite: every recorded x, v, pressure and contact force is finite.
        penetration: deepest node below a ground over the run (m; <= 0 if none).
        intrusion: deepest node inside another ring's centreline over the run (m; <= 0 if none).
        energy_growth: largest rise of the total energy (kinetic + elastic + gas + gravity, J, summed
            over rings) above its start value, divided by the start value of sum |energy parts|.
        collision_gain: energy the collision impulses' push-out created over the run
            (``SimulationStats.collision_gain``), in the same units: the one source of energy a
            scene without actuation has, so ``energy_growth`` may reach it.
        energy_removed: energy the stepper's energy budget removed (``SimulationStats.energy_removed``),
            in the same units.
        steps, rejections: accepted steps and rejected steps by reason (SimulationStats).
    """

    reached_end: bool
    error: str
    finite: bool
    penetration: float
    intrusion: float
    energy_growth: float
    collision_gain: float
    energy_removed: float
    steps: int
    rejections: dict = field(default_factory=dict)
    traj: object = field(default=None, repr=False)

    @property
    def documented(self):
        """The run reached t_end, or stopped with a SimulationError that names why and what to change."""
        return self.reached_end or any(name in self.error for name in DOCUMENTED_ERRORS)

    def problems(self):
        """Human-readable list of violated invariants (empty: the run is stable)."""
        out = []
        if not self.finite:
            out.append("non-finite state")
        if self.penetration > GROUND_TOLERANCE:
            out.append(f"ground penetration {self.penetration:.3g} m")
        if self.intrusion > 0.0:
            out.append(f"ring intrusion {self.intrusion:.3g} m")
        if self.energy_growth > ENERGY_ROUND_OFF + self.collision_gain:
            out.append(
                f"energy growth {self.energy_growth:.3g} (relative; push-out {self.collision_gain:.3g})"
            )
        if not self.documented:
            out.append(f"undocumented stop: {self.error!r}")
        return out


def audit(scene, t_end, x0=None, v0=None, output_dt=None):
    """Run ``simulate(scene, t_end, ...)`` and measure its invariants (see :class:`Audit`)."""
    error = ""
    try:
        traj = simulate(scene, t_end, x0=x0, v0=v0, output_dt=output_dt)
    except SimulationError as exc:
        traj = exc.trajectory
        error = str(exc)
    return audit_trajectory(traj, t_end, error)


def audit_trajectory(traj, t_end, error=""):
    """Invariants of a recorded trajectory (see :class:`Audit`)."""
    scene = traj.scene
    finite = bool(
        np.all(np.isfinite(traj.x))
        and np.all(np.isfinite(traj.v))
        and np.all(np.isfinite(traj.pressure))
        and np.all(np.isfinite(traj.contact_force))
    )
    penetration = 0.0
    for nx, ny, d, _ in ground_array(scene.grounds)[:, :4]:  # normal, offset at t = 0, friction
        depth = d - (traj.x[..., 0] * nx + traj.x[..., 1] * ny)
        penetration = max(penetration, float(depth.max()))
    intrusion = 0.0
    if len(scene.rings) > 1 and scene.ring_collision and finite:
        thickness = np.array([r.thickness for r in scene.rings])
        cw = build_collision_workspace(len(scene.rings), scene.rings[0].n_nodes)
        for x in traj.x:
            count = find_contacts(np.ascontiguousarray(x), thickness, cw)
            if count:
                intrusion = max(intrusion, float(-cw.contacts[:count, 5].min()))
    growth = np.inf
    gain = removed = 0.0
    if finite:
        energy = traj.energy()
        total = energy["total"].sum(axis=-1)
        scale = sum(np.abs(energy[k][0]).sum() for k in energy if k != "total")
        growth = float((total - total[0]).max() / scale)
        gain = traj.stats.collision_gain / scale
        removed = traj.stats.energy_removed / scale
    s = traj.stats
    return Audit(
        reached_end=not error and abs(traj.t[-1] - t_end) <= 1e-9 * t_end,
        error=error,
        finite=finite,
        penetration=penetration,
        intrusion=intrusion,
        energy_growth=growth,
        collision_gain=gain,
        energy_removed=removed,
        steps=s.steps,
        rejections=dict(s.rejections),
        traj=traj,
    )
