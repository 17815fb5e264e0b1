"""The env's batch (``ballenv.envs.batch``): the reward (the documented tolerance of the predicted
apex, bounded, never a gain from ending an episode early) and the actuation spread over the control
step (the pump's gas ramp, the paddle's spread strike)."""

import math

import gymnasium as gym
import numpy as np
import pytest

import ballenv  # noqa: F401  (registers the env)
from ballenv.controllers import PaddleDribble, PressurePump
from ballenv.envs.batch import (
    ENVS_PER_LINE,
    BallBatch,
    env_model,
    guided_chunks,
)
from ballenv.envs.inflated_ball import InflatedBallEnv
from ballenv.envs.task import REWARD_AT_MARGIN, height_reward
from ballenv.physics.base.layout import CLOCK_T, PUSH_DELIVERED, PUSH_T_END, PUSH_T_START, RAMP_T_END
from ballenv.physics.base.ring import total_mass
from ballenv.physics.build import build_workspace
from ballenv.physics.step.actuation import set_gas

MODES = ("pressure", "paddle")


def test_height_reward_is_deepmind_controls_gaussian_tolerance():
    assert height_reward(0.0, 0.5) == 1.0
    assert height_reward(0.5, 0.5) == pytest.approx(REWARD_AT_MARGIN, rel=1e-12)
    assert height_reward(0.25, 0.5) == pytest.approx(REWARD_AT_MARGIN**0.25, rel=1e-12)
    errors = np.linspace(0.0, 3.0, 31)
    values = [height_reward(e, 0.5) for e in errors]
    assert all(0.0 < v <= 1.0 for v in values)
    assert np.all(np.diff(values) < 0.0)


@pytest.mark.parametrize("mode", MODES)
def test_reward_is_in_zero_one_and_is_the_sum_of_its_terms(mode):
    env = gym.make("InflatedBall-v3", action_mode=mode)
    env.reset(seed=4)
    env.action_space.seed(4)
    rewards = []
    for _ in range(400):
        _, reward, terminated, truncated, info = env.step(env.action_space.sample())
        terms = [v for k, v in info.items() if k.startswith("reward_")]
        assert reward == pytest.approx(sum(terms), abs=1e-15)
        rewards.append(reward)
        if terminated or truncated:
            env.reset()
    rewards = np.array(rewards)
    assert np.all((rewards >= 0.0) & (rewards <= 1.0))
    assert rewards.max() > 0.5 and rewards.min() < 0.5  # random actions do reach and miss the target


def _tolerance(height, target, margin):
    return math.exp(-0.5 * (math.sqrt(2 * math.log(10)) * abs(height - target) / target / margin) ** 2)


def test_reward_measures_the_ballistic_apex_rising_and_the_last_apex_falling():
    """Falling from rest, the reward is that of the start height (the ball's last apex, observed as
    ``last_apex``); rising after its first bounce, that of its ballistic apex ``y + vy^2 / 2g``;
    after that flight's apex, that of the apex event the env reported."""
    env = gym.make("InflatedBall-v3")
    obs, info = env.reset(seed=2)
    s = env.unwrapped.observation_structure
    target, margin = info["target_height"], env.unwrapped.config.reward_margin
    g = env.unwrapped.config.gravity
    start = float(obs[s["centre_of_mass_position"]][1])
    assert obs[s["last_apex"]][0] == pytest.approx(start, rel=1e-6)
    phases = {"falling": 0, "rising": 0, "after apex": 0}
    apex = None
    for _ in range(200):
        obs, reward, _, _, info = env.step(np.array([0.0], dtype=np.float32))
        y = float(obs[s["centre_of_mass_position"]][1])
        vy = float(obs[s["centre_of_mass_velocity"]][1])
        flying = not obs[s["ground_normal_force"]].any()
        if info["apex_count"]:
            apex = info["apex_height"]
            assert obs[s["last_apex"]][0] == pytest.approx(apex, rel=1e-6)
        if flying and apex is None and vy < 0.0 and phases["rising"] == 0:
            phases["falling"] += 1
            assert reward == pytest.approx(_tolerance(start, target, margin), rel=1e-5)
        elif flying and vy > 0.0:
            phases["rising"] += 1
            assert reward == pytest.approx(_tolerance(y + 0.5 * vy * vy / g, target, margin), rel=1e-4)
        elif flying and apex is not None:
            phases["after apex"] += 1
            assert reward == pytest.approx(_tolerance(apex, target, margin), rel=1e-5)
            break
    assert min(phases.values()) > 0, phases


def test_reward_favours_the_paddle_strike_that_hits_the_target():
    """The dribbler's strike sized for the bounce's true loss (retention 0.7 of the energy) hits the
    target far better than one that ignores the loss (retention 1); the reward ranks them alike."""
    scores = {}
    for retention in (0.7, 1.0):
        env = gym.make("InflatedBallPaddle-v3")
        config = env.unwrapped.config
        dribble = PaddleDribble(
            env.unwrapped.observation_structure, total_mass(config.ring(config.initial_pressure)),
            retention=retention,
        )  # fmt: skip
        total, errors = 0.0, []
        for seed in range(2):
            obs, _ = env.reset(seed=100 + seed)
            dribble.reset()
            while True:
                obs, reward, terminated, truncated, info = env.step(dribble.act(obs))
                total += reward
                if info["apex_count"]:
                    errors.append(abs(info["apex_height"] - info["target_height"]) / info["target_height"])
                if terminated or truncated:
                    break
        scores[retention] = (np.mean(errors), total)
    assert scores[0.7][0] < 0.5 * scores[1.0][0]
    assert scores[0.7][1] > scores[1.0][1]


@pytest.mark.parametrize("seed", [0, 1])
def test_ending_early_never_pays(seed):
    """The pump keeps the ball bouncing; a quitter pumps alike for 150 steps, then lets the gas out
    until the ball rests (terminated early): its return is lower."""

    def episode(quit_at):
        env = gym.make("InflatedBall-v3")
        obs, _ = env.reset(seed=seed)
        pump = PressurePump(env.unwrapped.observation_structure)
        total, steps = 0.0, 0
        while True:
            action = pump.act(obs) if steps < quit_at else np.array([-1.0], dtype=np.float32)
            obs, reward, terminated, truncated, _ = env.step(action)
            total += reward
            steps += 1
            if terminated or truncated:
                return total, steps, terminated

    kept, kept_steps, _ = episode(quit_at=10**9)
    quit, quit_steps, quit_terminated = episode(quit_at=150)
    assert quit_terminated and quit_steps < kept_steps
    assert quit < kept


@pytest.mark.parametrize("n_envs", [1, 2, 9, 64, 257])
@pytest.mark.parametrize("threads", [2, 3])
def test_guided_chunks_cover_every_env_once_shrinking_and_line_aligned(n_envs, threads):
    bounds = guided_chunks(n_envs, threads)
    sizes = np.diff(bounds)
    assert bounds[0] == 0 and bounds[-1] == n_envs and (sizes >= 1).all()
    assert (np.diff(sizes) <= 0).all()  # largest first, single envs last
    big = sizes >= ENVS_PER_LINE
    assert (sizes[big] % ENVS_PER_LINE == 0).all()
    assert (np.asarray(bounds[:-1])[big] % ENVS_PER_LINE == 0).all()  # big chunks start on a line
    if n_envs >= 2 * threads:
        assert sizes[-1] == 1


def test_the_pump_ramps_the_gas_to_its_setpoint_by_the_end_of_each_control_step():
    env = InflatedBallEnv(action_mode="pressure")
    env.reset(seed=3)
    batch = env._batch
    n = env.config.n_nodes
    model = env_model(batch.model, 0)._replace(gas_constant=np.zeros(1), rest_energy=np.zeros(1))
    ws = build_workspace(n)
    budget, setpoint = batch.state.energy[0, 2], env.config.initial_pressure
    for k, action in enumerate([1.0, 1.0, -1.0] + [1.0] * 5):  # 34, 38, 34, 38, ... 50, 50 kPa
        held = batch.model.gas_constant[0]
        _, _, terminated, _, info = env.step(np.array([action], dtype=np.float32))
        assert not terminated
        moved, setpoint = info["pressure_setpoint"] != setpoint, info["pressure_setpoint"]
        # the amount of the new setpoint exactly, reached at the end of the control step
        set_gas(model, 0, setpoint, n, ws)  # what setting it at once would give
        assert batch.model.gas_constant[0] == model.gas_constant[0]
        assert batch.model.rest_energy[0] == model.rest_energy[0]
        assert (batch.model.gas_constant[0] != held) == moved
        assert batch.drive.ramp[0, RAMP_T_END] == -np.inf  # the ramp is over
        assert batch.clocks[0, CLOCK_T] == pytest.approx((k + 1) * env.dt, abs=1e-15)
        assert (batch.state.energy[0, 2] != budget) == moved  # the pump's work was credited
        budget = batch.state.energy[0, 2]
    assert setpoint == env.config.pressure_range[1] and not moved  # at the top: the gas stays


def _falling_strike(duration):
    """A paddle env whose ball falls in the air from 1.2 m, struck (J = 0.15 N s) at its second
    control step; returns the env, the ball's momentum (N s) before and after that step, and which
    nodes were within ``paddle_depth`` of the top when it struck."""
    env = InflatedBallEnv(action_mode="paddle", paddle_reach=5.0, paddle_strike_duration=duration)
    env.reset(seed=0)
    batch = env._batch
    env.step(np.array([-1.0], dtype=np.float32))  # let it fall one step: a falling ball is in reach
    x = batch.state.x[0]
    near_top = x[:, 1] >= x[:, 1].max() - env.config.paddle_depth
    m = batch.model.node_mass[0]
    before = m * batch.state.v[0].sum(axis=0)
    _, _, _, _, info = env.step(np.array([1.0], dtype=np.float32))
    assert info["paddle_impulse"] == pytest.approx(0.15, rel=1e-15)
    assert np.all(batch.state.active[0] == -1)  # still in the air: only gravity and the strike
    return env, before, m * batch.state.v[0].sum(axis=0), near_top


@pytest.mark.parametrize("duration", [1e-3, 3e-3, 1e-2])
def test_a_paddle_strike_delivers_exactly_its_impulse_over_its_duration(duration):
    env, before, after, near_top = _falling_strike(duration)
    batch = env._batch
    weight = total_mass(env.config.ring(env.config.initial_pressure)) * 9.81
    change = after - before - np.array([0.0, -weight * env.dt])
    np.testing.assert_allclose(change, [0.0, -0.15], rtol=0.0, atol=1e-13)
    push = batch.drive.push[0]
    assert push[PUSH_T_START] == pytest.approx(env.dt, abs=1e-15)
    assert push[PUSH_T_END] == push[PUSH_T_START] + duration
    assert push[PUSH_DELIVERED] == 1.0
    np.testing.assert_array_equal(batch.drive.pushed[0], near_top)  # the same nodes as at once


def test_a_spread_strike_is_a_different_motion_of_the_same_momentum():
    short, _, short_after, _ = _falling_strike(1e-4)
    spread, _, spread_after, _ = _falling_strike(1e-2)
    np.testing.assert_allclose(short_after, spread_after, rtol=0.0, atol=1e-13)
    shape = np.abs(short._batch.state.x[0] - spread._batch.state.x[0]).max()
    assert shape > 1e-4  # m: the wall took the strike differently


@pytest.mark.parametrize("duration", [0.0, 0.0101, float("nan"), -1e-3])
def test_paddle_strike_duration_out_of_range_names_the_keyword_and_its_range(duration):
    message = rf"^InflatedBall-v3\.paddle_strike_duration = {duration!r} is out of range: must be a finite "
    message += r"number in \(0, 0\.01\] s \(at most one control step, 1 / control_frequency\)$"
    with pytest.raises(ValueError, match=message):
        InflatedBallEnv(action_mode="paddle", paddle_strike_duration=duration)


@pytest.mark.parametrize("action", [-1.0, -0.8])
def test_the_paddle_strikes_only_a_ball_in_flight(action):
    """The paddle in reach everywhere (``paddle_reach`` 5 m): a falling ball in flight is in reach
    (unless struck already in that flight), a ball touching the ground never, even while its centre
    still moves down as it squashes (where a strike gained ``v J`` at the landing speed); every
    strike delivered started from a step whose observation said in reach."""
    env = gym.make("InflatedBallPaddle-v3", paddle_reach=5.0, target_height_range=(0.5, 0.51))
    s = env.unwrapped.observation_structure
    obs, _ = env.reset(seed=3)
    squashing = falling_in_flight = strikes = 0
    for _ in range(400):
        in_reach = obs[s["paddle_in_reach"]][0] == 1.0
        obs, _, terminated, truncated, info = env.step(np.array([action], dtype=np.float32))
        if info["paddle_impulse"] > 0.0:
            assert in_reach
            strikes += 1
        contact = obs[s["ground_normal_force"]].sum() > 0.0
        falling = obs[s["centre_of_mass_velocity"]][1] < 0.0
        if contact:
            assert obs[s["paddle_in_reach"]][0] == 0.0
            squashing += falling
        elif falling and info["paddle_impulse"] == 0.0 and action == -1.0:
            assert obs[s["paddle_in_reach"]][0] == 1.0  # never struck: in reach all the way down
            falling_in_flight += 1
        if terminated or truncated:
            break
    assert squashing > 0  # the case of the rule: on the ground, centre moving down
    if action == -1.0:
        assert strikes == 0 and falling_in_flight > 20
    else:
        assert strikes >= 3  # one per flight


@pytest.mark.parametrize("mode", MODES)
def test_a_copied_env_steps_exactly_as_its_source(mode):
    """Copies of an env mid-episode (in flight or squashed on the ground, the gas ramping, a strike
    under way) step to the bit as the env itself does, whatever row they land in."""
    env = InflatedBallEnv(action_mode=mode)
    env.reset(seed=5)
    rng = np.random.default_rng(5)
    for _ in range(37):
        env.step(rng.uniform(-1.0, 1.0, size=1).astype(np.float32))
    source = env._batch
    low, high = env.config.observation_bounds()
    copies = BallBatch(env.config.scene(), 3, env.config.task_settings(), low, high)
    copies.copy_env(source, 0, [0, 2])
    for _ in range(60):
        action = rng.uniform(-1.0, 1.0)
        source.step(np.array([action]))
        copies.step(np.array([action, 0.0, action]), np.array([True, False, True]))
        for row in (0, 2):
            np.testing.assert_array_equal(copies.obs[row], source.obs[0])
            np.testing.assert_array_equal(copies.task.reward[row], source.task.reward[0])
            np.testing.assert_array_equal(copies.state.x[row], source.state.x[0])
    assert copies.task.steps[1] == 0  # the row not copied, not stepped, is untouched


def test_copy_env_between_batches_of_different_balls_is_refused():
    small, large = InflatedBallEnv(fidelity="fast"), InflatedBallEnv(fidelity="balanced")
    with pytest.raises(ValueError, match="32 nodes .* 64 .* must be equal"):
        large._batch.copy_env(small._batch, 0, [0])


def test_the_compiled_step_takes_the_batchs_records_by_reference():
    from ballenv.envs.batch import step_batch
    from ballenv.physics.base.jit import python_entry
    from ballenv.physics.base.record_ref import RecordRefType

    env = InflatedBallEnv(action_mode="pressure")
    env.reset(seed=0)
    env.step(np.array([0.5], dtype=np.float32))
    batch = env._batch
    records = (batch.model, batch.state, batch.trial, batch.drive)
    assert all(ref.record is r for ref, r in zip(batch._refs, records, strict=True))  # the batch's own arrays
    signatures = [s for s in python_entry(step_batch).overloads if len(s) == 20]
    assert signatures  # the step compiled for these arguments
    for signature in signatures:
        # model, workspace, state, trial state, drive: one pointer each, not their ~100 arrays
        assert all(isinstance(signature[k], RecordRefType) for k in (0, 2, 3, 4, 5))
