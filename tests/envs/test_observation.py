"""The observation layout, declared once in ``ballenv.envs.observation``: its slices tile the vector,
its bounds fit it, the compiled code writes what each name says, and the env's docstring agrees."""

import re

import gymnasium as gym
import numpy as np
import pytest

import ballenv  # noqa: F401  (registers the env)
from ballenv.envs import batch as ball_batch
from ballenv.envs import observation
from ballenv.envs.config import BallEnvConfig
from ballenv.envs.inflated_ball import InflatedBallEnv
from ballenv.envs.numerics import ENV_FIDELITIES
from ballenv.envs.vector import InflatedBallVectorEnv

MODES = ("pressure", "paddle")
NODE_COUNTS = sorted({preset["n_nodes"] for preset in ENV_FIDELITIES.values()} | {3, 7})


@pytest.mark.parametrize("paddle", [False, True])
@pytest.mark.parametrize("n_nodes", NODE_COUNTS)
def test_slices_tile_the_vector_without_gaps_or_overlaps(n_nodes, paddle):
    structure = observation.structure(n_nodes, paddle)
    assert list(structure) == [field.name for field in observation.fields(paddle)]
    end = 0
    for name, part in structure.items():
        assert part.start == end and part.stop > part.start and part.step is None, name
        end = part.stop
    assert end == observation.size(n_nodes, paddle)
    assert end == 5 * n_nodes + 8 + (3 if paddle else 0)  # the docstring's "(5 N + 8,)" and "+3"


@pytest.mark.parametrize("paddle", [False, True])
def test_compiled_field_starts_agree_with_the_structure(paddle):
    for n_nodes in NODE_COUNTS:
        for name, part in observation.structure(n_nodes, paddle).items():
            start = getattr(observation, "OBS_" + name.upper())
            assert observation.field_start(start, n_nodes) == part.start, name


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("fidelity", list(ENV_FIDELITIES))
def test_bounds_have_the_declared_size_and_values(mode, fidelity):
    config = BallEnvConfig(action_mode=mode, fidelity=fidelity)
    paddle = mode == "paddle"
    low, high = config.observation_bounds()
    size = observation.size(config.n_nodes, paddle)
    assert low.dtype == high.dtype == np.float32
    assert low.shape == high.shape == (size,)
    assert np.all(np.isfinite(low)) and np.all(np.isfinite(high)) and np.all(low < high)
    s = observation.structure(config.n_nodes, paddle)
    reach = np.float32(4.0 * config.largest_radius())
    assert np.all(high[s["node_position"]] == reach) and np.all(low[s["node_position"]] == -reach)
    assert list(low[s["centre_of_mass_position"]]) == [-config.arena_half_width, -1.0]
    assert list(high[s["centre_of_mass_position"]]) == [config.arena_half_width, config.arena_height]
    assert (low[s["pressure"]][0], high[s["pressure"]][0]) == (-101325.0, 1e7)
    assert tuple(low[s["target_height"]]) + tuple(high[s["target_height"]]) == pytest.approx(
        config.target_height_range
    )
    if paddle:
        assert high[s["paddle_impulse"]][0] == np.float32(config.paddle_max_impulse)


def _expected(env, info):
    """What each field of the current observation holds (Pa, m, m/s, N), from the env's state."""
    batch = env.unwrapped._batch
    x = batch.state.x[0]
    v = batch.state.v[0]
    normal = batch.model.grounds[0, :2]
    out = {
        "node_position": (x - x.mean(axis=0)).reshape(-1),
        "node_velocity": (v - v.mean(axis=0)).reshape(-1),
        "centre_of_mass_position": x.mean(axis=0) - (0.0, batch.task.ground_height),
        "centre_of_mass_velocity": v.mean(axis=0),
        "ground_normal_force": batch.state.contact_force[0] @ normal,
        "pressure": [ball_batch.ring_pressure(batch.model, 0, x)],  # the simulator's gas law
        "target_height": [info["target_height"]],
        "last_apex": [batch.task.last_apex[0]],
    }
    if env.unwrapped.config.action_mode == "paddle":
        out["paddle_height"] = [info["target_height"] + batch.task.rest_radius[0]]
        config = env.unwrapped.config
        reach = abs(x[:, 1].max() - out["paddle_height"][0]) <= config.paddle_reach
        falling = v[:, 1].mean() < 0.0
        out["paddle_in_reach"] = [float(reach and falling and not batch.task.struck[0])]
        out["paddle_impulse"] = [info.get("paddle_impulse", 0.0)]
    return out


def _mismatches(env, obs, info, structure):
    """Names of ``structure`` whose slice of ``obs`` does not hold what the name says."""
    wrong = []
    for name, value in _expected(env, info).items():
        value = np.asarray(value, dtype=float)
        got = obs[structure[name]]
        if got.shape != value.shape or not np.allclose(got, value, rtol=1e-5, atol=1e-5):
            wrong.append(name)
    return wrong


def _step_until_struck(env, steps=300):
    """Step with action +1 until the paddle strikes (paddle mode) or the ball touches the ground."""
    paddle = env.unwrapped.config.action_mode == "paddle"
    for _ in range(steps):
        obs, _, terminated, _, info = env.step(np.array([1.0], dtype=np.float32))
        assert not terminated
        touching = np.any(env.unwrapped._batch.state.contact_force[0] != 0.0)
        if info["paddle_impulse"] > 0.0 if paddle else touching:
            return obs, info
    raise AssertionError("no strike or touchdown")


@pytest.mark.parametrize("mode", MODES)
def test_each_named_slice_holds_what_its_name_says(mode):
    env = gym.make("InflatedBall-v3", action_mode=mode)
    structure = env.unwrapped.observation_structure
    obs, info = env.reset(seed=4)
    assert _mismatches(env, obs, info, structure) == []
    assert abs(obs[structure["node_position"]].sum()) < 1e-5
    assert obs[structure["pressure"]][0] == pytest.approx(env.unwrapped.config.initial_pressure, rel=1e-6)
    obs, info = _step_until_struck(env)
    assert _mismatches(env, obs, info, structure) == []
    if mode == "paddle":
        assert obs[structure["paddle_impulse"]][0] > 0.0
        assert obs[structure["paddle_in_reach"]][0] == 0.0  # one strike per flight
    else:
        assert obs[structure["ground_normal_force"]].sum() > 0.0


@pytest.mark.parametrize("mode", MODES)
def test_a_layout_that_disagrees_with_the_writer_is_caught(mode):
    env = InflatedBallEnv(action_mode=mode)
    env.reset(seed=4)
    obs, info = _step_until_struck(env)
    structure = env.observation_structure
    for first, second in [("pressure", "target_height"), ("node_position", "node_velocity")]:
        swapped = {**structure, first: structure[second], second: structure[first]}
        assert _mismatches(env, obs, info, swapped) == [first, second]


@pytest.mark.parametrize("mode", MODES)
def test_single_and_vector_envs_share_the_structure_and_keep_it_out_of_info(mode):
    env = InflatedBallEnv(action_mode=mode)
    venv = InflatedBallVectorEnv(num_envs=3, action_mode=mode)
    assert env.observation_structure == venv.observation_structure
    assert env.observation_structure == observation.structure(env.config.n_nodes, mode == "paddle")
    env.observation_structure.clear()  # a copy: the env's own map stays
    assert len(env.observation_structure) == len(observation.fields(mode == "paddle"))
    infos = [env.reset(seed=0)[1], env.step(np.zeros(1, dtype=np.float32))[4]]
    obs, info = venv.reset(seed=0)
    infos += [info, venv.step(np.zeros((3, 1)))[4]]
    assert all("observation_structure" not in i for i in infos)
    target = venv.observation_structure["target_height"]
    np.testing.assert_array_equal(obs[:, target][:, 0], info["target_height"].astype(np.float32))


def _docstring_rows():
    """(name, per node, description, unit) of the rows of InflatedBallEnv's observation table."""
    section = InflatedBallEnv.__doc__.split("## Observation Space")[1].split("## Rewards")[0]
    rows = []
    for line in section.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        match = re.fullmatch(r"(\w+)(?: \((2N|N|paddle)\))?", cells[0]) if len(cells) == 4 else None
        if match and match.group(1) != "Slice":
            per_node = {"2N": 2, "N": 1}.get(match.group(2), 0)
            rows.append((match.group(1), per_node, cells[1], cells[2]))
    return rows


def test_docstring_table_matches_the_declaration():
    declared = [
        (f.name, f.per_node, f.description, f.unit) for f in observation.FIELDS + observation.PADDLE_FIELDS
    ]
    assert _docstring_rows() == declared


def test_the_paddle_strikes_once_per_flight():
    """Action +1 held for 3 s: one strike between two touchdowns, and a strike in more than one
    flight (striking resumes once the ball has touched the ground)."""
    env = gym.make("InflatedBallPaddle-v3")
    env.reset(seed=1)
    strikes, flights_struck = 0, 0
    for _ in range(300):
        _, _, terminated, truncated, info = env.step(np.array([1.0], dtype=np.float32))
        strikes += info["paddle_impulse"] > 0.0
        assert strikes <= 1
        if np.any(env.unwrapped._batch.state.contact_force[0] != 0.0):
            flights_struck += strikes
            strikes = 0
        if terminated or truncated:
            break
    assert flights_struck >= 2
