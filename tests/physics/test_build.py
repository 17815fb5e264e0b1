"""The one builder: what ``build`` makes of a scene, for a simulation and for the env's batch."""

import gymnasium as gym
import numpy as np
import pytest

import ballenv  # noqa: F401  (registers the env)
from ballenv.physics import Ground, Ring, Scene, Simulation
from ballenv.physics.build import build, build_model, scene_effects, simulation_workspace, tiled_model
from ballenv.physics.model import PER_RING_FIELDS, Model
from ballenv.physics.step.integrator import build_solver

TWO_RINGS = Scene(
    rings=[Ring(n_nodes=12, position=(0.0, 0.5)), Ring(n_nodes=12, position=(0.5, 0.5), radius=0.08)],
    grounds=[Ground(friction=0.4)],
    damping=2.0,
)


def test_build_makes_the_model_solver_and_separate_zeroed_states_of_every_ring():
    built = build(TWO_RINGS)
    assert built.model.node_mass.shape == (2,) and built.model.grounds.shape[0] == 1
    assert built.solver == build_solver(TWO_RINGS)
    for state in (built.state, built.trial):
        assert state.x.shape == state.v.shape == state.a.shape == (2, 12, 2)
        assert not state.x.any() and (state.active == -1).all()
    assert not np.shares_memory(built.state.x, built.trial.x)


def test_copies_repeat_a_one_ring_scene_per_ring_and_share_its_scalars():
    scene = Scene(rings=[Ring(n_nodes=10, pressure=20e3)], grounds=[Ground()])
    one, three = build(scene).model, build(scene, copies=3).model
    for name in Model._fields:
        a, b = getattr(one, name), getattr(three, name)
        if name in PER_RING_FIELDS:
            assert len(b) == 3 and all(np.array_equal(b[k], a[0]) for k in range(3)), name
        else:
            assert np.array_equal(a, b), name
    assert build(scene, copies=3).state.x.shape == (3, 10, 2)
    assert np.array_equal(tiled_model(one, 3).rest_energy, three.rest_energy)


def test_simulation_and_env_batch_are_built_by_it():
    sim = Simulation(TWO_RINGS)
    reference = build_model(TWO_RINGS)
    for name in Model._fields:
        assert np.array_equal(getattr(sim.model, name), getattr(reference, name)), name
    env = gym.make("InflatedBall-v3", fidelity="fast")
    ball = env.unwrapped
    batch = ball.planning_copies(4)
    scene = ball.config.scene()
    expected = build(scene, copies=4)
    for name in Model._fields:
        assert np.array_equal(getattr(batch.model, name), getattr(expected.model, name)), name
    assert batch.solver == expected.solver
    env.close()


@pytest.mark.parametrize(
    ("changes", "barrier", "doubling"),
    [
        ({"self_intersection": "reject"}, False, False),
        ({"self_intersection": "barrier"}, True, False),
        ({"self_intersection": "reject", "contact_error": "doubling", "rtol": 0.01}, False, True),
    ],
)
def test_the_simulation_workspace_holds_only_what_the_scene_asks_for(changes, barrier, doubling):
    scene = Scene(rings=[Ring(n_nodes=12)], grounds=[Ground()], **changes)
    built = build(scene)
    ws = simulation_workspace(scene, built.model, built.solver)
    assert (ws.barrier is not None) == barrier
    assert (ws.doubling is not None) == doubling
    assert ws.ring_pairs is None and ws.ring_contact is None  # one ring: no pairs of rings


def test_scene_effects_names_the_forces_then_the_constraints_a_scene_switches_on():
    assert scene_effects(TWO_RINGS) == (
        "stretching", "bending", "pressure", "gravity", "damping", "ground", "friction", "ring_collision",
    )  # fmt: skip
    bare = Scene(rings=[Ring(n_nodes=8, pressure=None)], gravity=0.0)
    assert scene_effects(bare) == ("stretching", "bending")
