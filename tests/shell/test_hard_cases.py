"""The 3-D ball's hard cases, each with both integrators: a 30 m/s impact, a ball with no gauge
pressure, a ball squeezed into a narrow wedge at 10 m/s, a ball spinning at 300 rad/s dropped
onto a rough floor, two balls meeting head-on at 20 m/s each and a half-deflated ball (half the
default ball's gas) crumpling on the floor with self-contact.

For every run: ``t_end`` reached (no ``SimulationError``), every recorded state finite, every
vertex above every ground, the shells' energy (implicit.total_energy, summed) never above its
start by more than round-off (1e-10 of the gas's ``p_abs V0``: nothing in these scenes adds
energy), and the isothermal gas law ``(p + p_atm) V`` held to 1e-12. Each case also shows it is as
hard as named.
"""

import math
from dataclasses import replace

import numpy as np
import pytest

from ballenv.shell import Ground, Scene, Shell, simulate
from ballenv.shell.simulation import build
from ballenv.shell.skin.gas import volume
from ballenv.shell.skin.model import build_model
from ballenv.shell.step.implicit import total_energy

from .meshcheck import check_apart, check_self

INTEGRATORS = ("generalized_alpha", "backward_euler")
HALF_GAS = (55e3 + 101325.0) / 2.0 - 101325.0  # Pa: half the default ball's gas at its rest shape
WEDGE = math.radians(60.0)  # each wall's tilt from the horizontal: a V opening 60 degrees
WALLS = (
    Ground(normal=(-math.sin(WEDGE), 0.0, math.cos(WEDGE)), friction=0.5),
    Ground(normal=(math.sin(WEDGE), 0.0, math.cos(WEDGE)), friction=0.5),
)


def cases():
    """name -> (scene, t_end s, x0 or None)."""
    floor, rough = (Ground(friction=0.5),), (Ground(friction=0.8),)
    spinning = Shell(position=(0, 0, 0.135), velocity=(2.0, 0, -3.0), angular_velocity=(0, 300.0, 0))
    pair = [
        Shell(position=(-0.14, 0, 0), velocity=(20.0, 0, 0)),
        Shell(position=(0.14, 0, 0), velocity=(-20.0, 0, 0)),
    ]
    half = Shell(pressure=HALF_GAS, position=(0, 0, 0.3))  # from its rest sphere: no inflated shape
    sphere = (build_model(half).rest + half.position)[None]
    return {
        "impact_30_m_s": (Scene([Shell(position=(0, 0, 0.14), velocity=(0, 0, -30.0))], floor), 0.012, None),
        "pressure_zero": (Scene([Shell(pressure=0.0, position=(0, 0, 0.4))], floor), 0.4, None),
        "wedge_10_m_s": (Scene([Shell(position=(0, 0, 0.30), velocity=(0, 0, -10.0))], WALLS), 0.03, None),
        "spin_300_rad_s": (Scene([spinning], rough), 0.05, None),
        "two_balls_20_m_s": (Scene(pair, gravity=0.0), 0.012, None),
        "half_deflated": (Scene([half], floor, self_contact=True), 0.3, sphere),
    }  # fmt: skip


CASES = cases()


def audit(scene, t_end, x0=None):
    """The run and its invariants (module doc)."""
    traj = simulate(scene, t_end=t_end, x0=x0)
    assert traj.t[-1] == pytest.approx(t_end)
    assert np.all(np.isfinite(traj.x)) and np.all(np.isfinite(traj.v))
    for gr in scene.grounds:
        assert (traj.x @ np.array(gr.normal)).min() - gr.height > 0.0
    _, steps = build(scene)
    energy = sum(
        np.array([total_energy(st, x, v) for x, v in zip(traj.x[:, k], traj.v[:, k], strict=True)])
        for k, st in enumerate(steps)
    )
    gas = sum(st.problem.model.absolute_pressure[0] * st.problem.model.rest_volume for st in steps)
    assert energy.max() <= energy[0] + 1e-10 * gas
    for k, st in enumerate(steps):
        model = st.problem.model
        vol = np.array([volume(x, model.triangles) for x in traj.x[:, k]])
        invariant = (traj.pressure[:, k] + scene.atmospheric_pressure) * vol
        assert np.abs(invariant / invariant[0] - 1.0).max() < 1e-12
    return traj


@pytest.mark.parametrize("integrator", INTEGRATORS)
@pytest.mark.parametrize("name", list(CASES))
def test_hard_case_is_stable(name, integrator):
    scene, t_end, x0 = CASES[name]
    traj = audit(replace(scene, integrator=integrator), t_end, x0)
    mass = build(scene)[1][0].problem.model.mass
    centre_v = np.einsum("i,tij->tj", mass / mass.sum(), traj.v[:, 0])
    touchdowns = [e for e in traj.events if e[2] == "touchdown"]
    if name == "impact_30_m_s":  # it hits at 30 m/s and is thrown back up
        assert touchdowns and centre_v[0, 2] == pytest.approx(-30.0) and centre_v[-1, 2] > 5.0
    elif name == "pressure_zero":  # no gas pressure holds it: the skin alone
        assert traj.pressure[0, 0] == pytest.approx(0.0, abs=1e-6) and touchdowns
    elif name == "wedge_10_m_s":  # both walls press it: the gas is squeezed
        for gr in WALLS:
            assert (traj.x[:, 0] @ np.array(gr.normal)).min() < 1e-3
        assert traj.pressure[:, 0].max() > 1.05 * traj.pressure[0, 0]
    elif name == "two_balls_20_m_s":  # they meet, bounce apart, keep their momentum, never overlap
        momentum = np.einsum("i,tsij->tj", mass, traj.v)
        assert np.abs(momentum).max() < 1e-10 * mass.sum() * 20.0
        assert traj.v[-1, 0, :, 0].mean() < 0.0 < traj.v[-1, 1, :, 0].mean()
        triangles = build(scene)[1][0].problem.model.triangles
        gap = np.linalg.norm(traj.x[:, 0].mean(axis=1) - traj.x[:, 1].mean(axis=1), axis=1)
        for x in traj.x[gap < 0.27][::3]:  # a third of the records in contact (inflated radius 0.127 m)
            wind, crossings, closest = check_apart(x[0], x[1], triangles)
            assert wind < 0.5 and crossings == 0 and closest > 0.0
    elif name == "half_deflated":  # the atmosphere crumples it; it never passes through itself
        triangles = build(scene)[1][0].problem.model.triangles
        vol = np.array([volume(x, triangles) for x in traj.x[:, 0]])
        assert vol.min() < 0.8 * vol[0]
        for x in traj.x[:: max(1, len(traj.x) // 40), 0]:
            crossings, closest = check_self(x, triangles)
            assert crossings == 0 and closest > 0.0
    else:  # it lands spinning at 300 rad/s and the floor's friction takes spin
        x, v = traj.x[:, 0], traj.v[:, 0]
        r = x - np.einsum("i,tij->tj", mass / mass.sum(), x)[:, None, :]
        spin = np.einsum("i,tij->tj", mass, np.cross(r, v - centre_v[:, None, :]))[:, 1]
        assert spin[-1] < spin[0] and touchdowns
