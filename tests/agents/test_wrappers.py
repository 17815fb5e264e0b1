"""agents.wrappers: the ball-state observation, the residual on the pump, and a run trained behind a
wrapper evaluates behind it."""

import json
import pathlib
import subprocess
import sys

import gymnasium as gym
import numpy as np
import pytest

import ballenv  # noqa: F401  (registers the env)
from agents.evaluate import evaluate
from agents.policies import HeuristicPolicy
from agents.wrappers import (
    AMPLITUDE_SPAN,
    RESIDUAL_SCALE,
    SHAPE_MODES,
    STRIKE_CORRECTION,
    BallLandingObservation,
    BallShapeObservation,
    BallStateObservation,
    PaddleStrike,
    PumpAmplitude,
    PumpApex,
    ResidualPump,
    radial_modes,
    ring_angle,
    rotation_phase,
    wrapper_class,
)

ROOT = pathlib.Path(__file__).resolve().parents[2]


def _into_first_contact(env, raw):
    """Reset ``env`` (a wrapped env) and ``raw`` with seed 5 and take the same 60 actions of 0.3 (into
    the first ground contact): their last observations."""
    obs, _ = env.reset(seed=5)
    full, _ = raw.reset(seed=5)
    for _ in range(60):
        action = np.array([0.3], dtype=np.float32)
        obs, *_ = env.step(action)
        full, *_ = raw.step(action)
    return obs, full


def test_ball_state_observation_refuses_another_env():
    with pytest.raises(TypeError, match="not an InflatedBall env"):
        BallStateObservation(gym.make("CartPole-v1"))


@pytest.mark.parametrize("mode", ["pressure", "paddle"])
def test_ball_state_keeps_the_body_fields_and_the_total_ground_force(mode):
    raw = gym.make("InflatedBall-v3", action_mode=mode)
    env = BallStateObservation(gym.make("InflatedBall-v3", action_mode=mode))
    s = raw.unwrapped.observation_structure
    assert env.observation_space.shape == ((9,) if mode == "pressure" else (12,))
    obs, full = _into_first_contact(env, raw)
    assert env.observation_space.contains(obs)
    assert obs[0:2] == pytest.approx(full[s["centre_of_mass_position"]])
    assert obs[2:4] == pytest.approx(full[s["centre_of_mass_velocity"]])
    assert obs[6] == full[s["target_height"]][0] and obs[7] == full[s["last_apex"]][0]
    assert obs[-1] == pytest.approx(full[s["ground_normal_force"]].sum(), rel=1e-5)
    if mode == "paddle":
        assert obs[8:11] == pytest.approx(np.concatenate([full[s[k]] for k in ("paddle_height",
                                          "paddle_in_reach", "paddle_impulse")]))  # fmt: skip


def ring_observation(env, radius, deform=lambda angle: 0.0, rate=lambda angle: 0.0):
    """A raw observation of the env under ``env`` whose nodes lie at ``radius + deform(angle)`` (m) from the
    centre of mass, moving radially at ``rate(angle)`` (m/s), the other entries 0."""
    s = env.unwrapped.observation_structure
    n = (s["node_position"].stop - s["node_position"].start) // 2
    angle = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False) + 0.1
    direction = np.column_stack([np.cos(angle), np.sin(angle)])
    obs = np.zeros(env.unwrapped.observation_space.shape, dtype=np.float32)
    distance = np.broadcast_to(radius + deform(angle), angle.shape)
    speed = np.broadcast_to(rate(angle), angle.shape)
    obs[s["node_position"]] = (distance[:, None] * direction).ravel()
    obs[s["node_velocity"]] = (speed[:, None] * direction).ravel()
    return obs


def test_radial_modes_are_the_fourier_coefficients():
    angle = np.linspace(0.0, 2.0 * np.pi, 32, endpoint=False)
    values = 0.5 + 0.2 * np.cos(2 * angle) - 0.3 * np.sin(3 * angle)
    modes = radial_modes(values, angle, 4)
    assert modes == pytest.approx([0.5, 0, 0, 0.2, 0, 0, -0.3, 0, 0], abs=1e-12)


@pytest.mark.parametrize("mode", ["pressure", "paddle"])
def test_ball_shape_adds_the_ring_modes_to_the_ball_state(mode):
    raw = gym.make("InflatedBall-v3", action_mode=mode)
    env = BallShapeObservation(gym.make("InflatedBall-v3", action_mode=mode))
    body = BallStateObservation(gym.make("InflatedBall-v3", action_mode=mode))
    n_shape = 2 * (1 + 2 * SHAPE_MODES)
    assert env.observation_space.shape == (body.observation_space.shape[0] + n_shape,)
    obs, full = _into_first_contact(env, raw)
    assert env.observation_space.contains(obs)
    assert obs[:-n_shape] == pytest.approx(body.observation(full))
    assert obs[-n_shape:] == pytest.approx(env.shape_modes(full), abs=1e-6)


def test_a_round_ring_has_only_the_breathing_mode():
    env = BallShapeObservation(gym.make("InflatedBall-v3"))
    r, scale = env.radius, env.speed_scale
    shape = env.shape_modes(ring_observation(env, 1.1 * r, rate=lambda a: 0.5))
    displacement, rate = np.split(shape, 2)
    assert displacement[0] == pytest.approx(0.1, rel=1e-5)  # (1.1 R - R) / R
    assert rate[0] == pytest.approx(0.5 / scale, rel=1e-5)
    assert np.abs(displacement[1:]).max() < 1e-6 and np.abs(rate[1:]).max() < 1e-5


def test_a_squashed_ring_shows_in_mode_two():
    env = BallShapeObservation(gym.make("InflatedBall-v3"))
    r, scale = env.radius, env.speed_scale
    obs = ring_observation(env, r, deform=lambda a: 0.01 * np.cos(2 * a), rate=lambda a: -0.2 * np.cos(2 * a))
    displacement, rate = np.split(env.shape_modes(obs), 2)
    assert displacement[3] == pytest.approx(0.01 / r, rel=1e-3)  # c_2: wider than tall
    assert rate[3] == pytest.approx(-0.2 / scale, rel=1e-3)
    others = np.delete(np.arange(displacement.size), 3)
    assert np.abs(displacement[others]).max() < 1e-3 * 0.01 / r


@pytest.mark.parametrize("mode", ["pressure", "paddle"])
def test_ball_landing_adds_the_landing_phase_to_the_ball_state(mode):
    raw = gym.make("InflatedBall-v3", action_mode=mode)
    env = BallLandingObservation(gym.make("InflatedBall-v3", action_mode=mode))
    assert env.observation_space.shape == ((11,) if mode == "pressure" else (14,))
    obs, full = _into_first_contact(env, raw)
    assert env.observation_space.contains(obs)
    assert obs[:-2] == pytest.approx(BallStateObservation(raw).observation(full))
    assert np.hypot(obs[-2], obs[-1]) == pytest.approx(1.0, rel=1e-6)


def test_the_landing_phase_holds_in_flight_and_names_the_control_step_of_the_touch():
    """Released at rest, the ball falls ballistically: its time to landing (centre at one mean radius
    above the ground) falls by one control step per step, so the phase stays put, and the ground
    first pushes in the control step that time ends in."""
    raw = gym.make("InflatedBall-v3")
    env = BallLandingObservation(gym.make("InflatedBall-v3"))
    obs, _ = env.reset(seed=5)
    full, _ = raw.reset(seed=5)
    s, config = raw.unwrapped.observation_structure, raw.unwrapped.config
    nodes = full[s["node_position"]].reshape(-1, 2)
    height = full[s["centre_of_mass_position"]][1] - np.hypot(*nodes.T).mean()
    steps_to_landing = np.sqrt(2.0 * height / config.gravity) / config.control_dt
    assert 0.1 < steps_to_landing % 1.0 < 0.9  # not at a step's end, where one step either way is right
    assert np.arctan2(obs[-1], obs[-2]) % (2 * np.pi) == pytest.approx(
        2 * np.pi * (steps_to_landing % 1.0), abs=1e-4
    )
    phases, step = [], 0
    while full[s["ground_normal_force"]].sum() == 0.0:
        phases.append(np.arctan2(obs[-1], obs[-2]))
        obs, *_ = env.step(np.zeros(1, dtype=np.float32))
        full, *_ = raw.step(np.zeros(1, dtype=np.float32))
        step += 1
    assert np.ptp(phases) < 1e-3
    assert step == int(np.ceil(steps_to_landing))


def test_an_amplitude_step_is_one_bounce_of_the_pumps_timing():
    """Each agent step plays ``+-AMPLITUDE_SPAN a`` at every env step until the first flight apex after
    a landing: the observed last apex changes from one agent step to the next, and the rewards add."""
    env = PumpAmplitude(gym.make("InflatedBall-v3"))
    played, rewards, step = [], [], env.env.step

    def recorded(action):
        out = step(action)
        played.append(float(action[0]))
        rewards.append(float(out[1]))
        return out

    env.env.step = recorded
    obs, _ = env.reset(seed=3)
    apexes, total = [obs[7]], 0.0
    for _ in range(4):
        obs, reward, *_ = env.step(np.array([0.5], dtype=np.float32))
        apexes.append(obs[7])
        total += reward
    assert set(np.round(played, 6)) == {round(0.5 * AMPLITUDE_SPAN, 6), round(-0.5 * AMPLITUDE_SPAN, 6)}
    assert all(a != b for a, b in zip(apexes, apexes[1:], strict=False))
    assert 4 < len(played) and total == pytest.approx(sum(rewards))


def test_the_apex_reward_is_the_tolerance_of_the_apex_each_bounce_ends_in():
    """PumpApex plays the bounces PumpAmplitude plays; its reward is the tolerance of each bounce's
    apex error with the success tolerance as margin (bounded by 1), and the time limit's cut bounce
    gets the same tolerance of the apex the env's last reward rates."""
    from ballenv.envs.task import height_reward

    apex_env = PumpApex(gym.make("InflatedBall-v3", max_episode_steps=300))
    sum_env = PumpAmplitude(gym.make("InflatedBall-v3", max_episode_steps=300))
    apex_env.reset(seed=4)
    sum_env.reset(seed=4)
    truncated, action = False, np.array([0.5], dtype=np.float32)
    while not truncated:
        obs, reward, terminated, truncated, info = apex_env.step(action)
        same, total, *_ = sum_env.step(action)
        np.testing.assert_array_equal(obs, same)
        assert not terminated and 0.0 <= reward <= 1.0 < total
        if not truncated:
            error = abs(info["apex_height"] - info["target_height"]) / info["target_height"]
            assert reward == pytest.approx(height_reward(error, 0.05), rel=1e-12)
    # cut short: the error the env's last reward rates (margin 0.5), rated with margin 0.05
    error = 0.5 * np.sqrt(-2.0 * np.log(info["reward_height"])) / np.sqrt(2.0 * np.log(10.0))
    assert reward == pytest.approx(height_reward(error, 0.05), rel=1e-9)


def test_an_amplitude_played_step_by_step_is_the_stepped_episode():
    """``act`` (what ``agents.evaluate`` calls, one env step at a time) asks for an amplitude exactly
    where ``step`` would end an agent step, so a policy scores the same both ways."""
    env = PumpAmplitude(gym.make("InflatedBall-v3"))
    obs, _ = env.reset(seed=10_000)
    stepped, decisions, done = 0.0, 0, False
    while not done:
        action = np.array([0.4 + 0.1 * np.tanh(obs[7])], dtype=np.float32)
        obs, reward, terminated, truncated, _ = env.step(action)
        stepped += float(reward)
        decisions += 1
        done = terminated or truncated
    raw, player = gym.make("InflatedBall-v3"), PumpAmplitude(gym.make("InflatedBall-v3"))
    obs, _ = raw.reset(seed=10_000)
    player.restart()
    asked, played, done = [], 0.0, False

    def ask(wrapped):
        asked.append(wrapped)
        return np.array([0.4 + 0.1 * np.tanh(wrapped[7])], dtype=np.float32)

    while not done:
        obs, reward, terminated, truncated, _ = raw.step(player.act(obs, ask))
        played += float(reward)
        done = terminated or truncated
    assert len(asked) == decisions
    assert played == pytest.approx(stepped, rel=1e-12)


def test_the_amplitude_is_for_the_pressure_mode_only():
    with pytest.raises(ValueError, match="action_mode = 'paddle'"):
        PumpAmplitude(gym.make("InflatedBall-v3", action_mode="paddle"))


def test_a_wrapper_name_that_does_not_import_is_one_readable_error():
    assert wrapper_class(None) is None
    assert wrapper_class("agents.wrappers.BallStateObservation") is BallStateObservation
    assert wrapper_class("agents.wrappers.BallShapeObservation") is BallShapeObservation
    with pytest.raises(ValueError, match="env_wrapper = 'agents.wrappers.Nope'"):
        wrapper_class("agents.wrappers.Nope")


def test_a_zero_residual_is_the_pump():
    """Behind ``ResidualPump`` the action 0 at every step runs the episode the tuned pump runs on
    the raw env, and the agent sees the pump's action as its last entry."""
    env = ResidualPump(gym.make("InflatedBall-v3", max_episode_steps=150))
    raw = gym.make("InflatedBall-v3", max_episode_steps=150)
    pump = HeuristicPolicy(raw)
    body = BallStateObservation(raw)
    obs, _ = env.reset(seed=3)
    full, _ = raw.reset(seed=3)
    pump.reset(3)
    rewards, done = [], False
    while not done:
        action = pump.act(full)
        assert obs[-1] == action[0]
        np.testing.assert_array_equal(obs[:-1], body.observation(full))
        obs, r_wrapped, *_ = env.step(np.zeros(1, dtype=np.float32))
        full, r_raw, terminated, truncated, _ = raw.step(action)
        rewards.append((r_wrapped, r_raw))
        done = terminated or truncated
    assert len(rewards) == 150 and all(a == b for a, b in rewards)


def test_the_residual_corrects_the_pump_within_its_scale():
    env = ResidualPump(gym.make("InflatedBall-v3"))
    obs, _ = env.reset(seed=0)
    assert env.observation_space.shape == (10,) and env.observation_space.contains(obs)
    for a in (-1.0, 0.5, 1.0):
        expected = np.clip(obs[-1] + RESIDUAL_SCALE * a, -1.0, 1.0)
        assert env.action(np.array([a], dtype=np.float32))[0] == pytest.approx(expected)


def test_the_residual_is_for_the_pressure_mode_only():
    with pytest.raises(ValueError, match="action_mode = 'paddle' is invalid"):
        ResidualPump(gym.make("InflatedBall-v3", action_mode="paddle"))


# an observation wrapper and an action wrapper in the default run; ResidualPump, an action wrapper
# on the same path as PumpAmplitude, in make test-slow
@pytest.mark.parametrize(
    "wrapper",
    [
        "agents.wrappers.BallStateObservation",
        pytest.param("agents.wrappers.ResidualPump", marks=pytest.mark.slow),
        "agents.wrappers.PumpAmplitude",
    ],
)
def test_a_run_trained_behind_the_wrapper_is_evaluated_behind_it(tmp_path, wrapper):
    hp = {"n_steps": 64, "batch_size": 64, "n_epochs": 1, "env_wrapper": wrapper}
    command = [
        sys.executable, str(ROOT / "train.py"), "--n-envs", "1", "--total-timesteps", "128",
        "--eval-freq", "64", "--eval-episodes", "1", "--final-episodes", "1", "--no-baselines",
        "--log-dir", str(tmp_path), "--env-kwargs", json.dumps({"max_episode_steps": 60}),
        "--hyperparams", json.dumps(hp),
    ]  # fmt: skip
    done = subprocess.run(command, cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    run = tmp_path / "ppo_pressure_seed0"
    scores = json.loads((run / "scores.json").read_text())
    again = evaluate(str(run), {"max_episode_steps": 60}, episodes=1)
    assert again.episode_apex_errors == pytest.approx(scores[0]["episode_apex_errors"])
    assert again.episode_return == pytest.approx(_return_behind(wrapper_class(wrapper), run, 60))


def _return_behind(cls, run, steps):
    """The return of the first held-out episode (``agents.evaluate``'s seed) of ``run``'s best model
    stepping the env behind ``cls`` itself, as in training (observations normalised with the saved
    statistics)."""
    from stable_baselines3 import PPO

    from agents.evaluate import DEFAULT_SEED
    from agents.normalization import load

    model = PPO.load(run / "best_model.zip", device="cpu")
    normalize = load(run / "best_vecnormalize.npz")
    env = cls(gym.make("InflatedBall-v3", max_episode_steps=steps))
    obs, _ = env.reset(seed=DEFAULT_SEED)
    total, done = 0.0, False
    while not done:
        action, _ = model.predict(normalize.apply(obs), deterministic=True)
        obs, reward, terminated, truncated, _ = env.step(action)
        total += float(reward)
        done = terminated or truncated
    return total


def test_a_mistyped_wrapper_stops_train_before_any_run_folder(tmp_path):
    from agents.train import main as train_main

    with pytest.raises(SystemExit, match="env_wrapper = 'agents.wrappers.Nope'"):
        train_main(
            ["--log-dir", str(tmp_path), "--hyperparams", json.dumps({"env_wrapper": "agents.wrappers.Nope"})]
        )
    assert not any(tmp_path.iterdir())


def test_the_rotation_phase_predicts_where_the_nodes_sit_at_the_touch():
    """From a strike's observation, the landing rotation phase is the ring's phase (node spacings)
    at its first observed ground contact, to 0.03 spacings (the ring rolls a little within the
    10-ms step the touch falls in)."""
    env = gym.make("InflatedBall-v3", action_mode="paddle")
    ball = env.unwrapped
    s, g, policy = ball.observation_structure, ball.config.gravity, HeuristicPolicy(env)
    obs, _ = env.reset(seed=3)
    policy.reset(3)
    predicted, found = None, []
    for _ in range(400):
        obs, *_ = env.step(policy.act(obs))
        if obs[s["paddle_impulse"]][0] > 0.0:
            predicted = rotation_phase(obs, s, g)
        if predicted is not None and obs[s["ground_normal_force"]].sum() > 0.0:
            nodes = obs[s["node_position"]].reshape(-1, 2).astype(np.float64)
            found.append(
                ((len(nodes) * ring_angle(nodes) / (2.0 * np.pi)) % 1.0 - predicted + 0.5) % 1.0 - 0.5
            )
            predicted = None
    assert len(found) >= 5 and np.abs(found).max() < 0.03, found


def test_a_strike_step_corrects_the_scripted_strike_once_and_is_rewarded_by_its_bounce():
    """A reset plays idle until the ball is in reach; each agent step strikes ``b + 0.1 a`` (``b``
    the scripted paddle's strike, observed last) at its first env step, idle (-1) at the others, and
    ends when the ball is in reach again; its reward is the tolerance of the first apex after the
    strike (margin 0.05)."""
    from ballenv.envs.task import height_reward

    env = PaddleStrike(gym.make("InflatedBall-v3", action_mode="paddle"))
    played, apexes, step = [], [], env.env.step

    def recorded(action):
        out = step(action)
        played.append(float(action[0]))
        if out[4]["apex_count"]:
            apexes.append((len(played), out[4]["apex_height"], out[4]["target_height"]))
        return out

    env.env.step = recorded
    obs, _ = env.reset(seed=3)
    assert obs.shape == env.observation_space.shape == (26,) and obs[9] == 1.0  # in reach
    for k in range(4):
        start, base, action = len(played), env.base, 0.2 + 0.2 * k  # a strike, also where b = -1
        assert obs[-1] == np.float32(base) and -1.0 <= base < 0.5  # -1: the ball high, no strike
        obs, reward, terminated, truncated, _ = env.step(np.array([action], dtype=np.float32))
        assert not (terminated or truncated) and obs[9] == 1.0  # in reach again
        assert played[start] == pytest.approx(base + STRIKE_CORRECTION * action, abs=1e-6)
        assert set(played[start + 1 :]) == {-1.0}  # idle until the next decision
        first = next((h, t) for n, h, t in apexes if n > start)
        assert reward == pytest.approx(height_reward(abs(first[0] - first[1]) / first[1], 0.05), rel=1e-12)


def test_a_strike_played_step_by_step_is_the_stepped_episode():
    """``act`` asks for a correction exactly where ``step`` would end an agent step (and the reset's
    first), and plays the same env actions, so a policy scores the same both ways."""

    def policy(wrapped):
        return np.array([-0.2 + 0.2 * np.tanh(wrapped[7] - wrapped[6])], dtype=np.float32)

    env = PaddleStrike(gym.make("InflatedBall-v3", action_mode="paddle", max_episode_steps=400))
    stepped, step = [], env.env.step
    env.env.step = lambda action: (stepped.append(float(action[0])), step(action))[1]
    obs, _ = env.reset(seed=10_000)
    decisions, done = 0, False
    while not done:
        obs, _, terminated, truncated, _ = env.step(policy(obs))
        decisions += 1
        done = terminated or truncated
    raw = gym.make("InflatedBall-v3", action_mode="paddle", max_episode_steps=400)
    player = PaddleStrike(gym.make("InflatedBall-v3", action_mode="paddle"))
    obs, _ = raw.reset(seed=10_000)
    player.restart()
    asked, played, done = [], [], False

    def ask(wrapped):
        asked.append(wrapped)
        return policy(wrapped)

    while not done:
        action = player.act(obs, ask)
        played.append(float(action[0]))
        obs, _, terminated, truncated, _ = raw.step(action)
        done = terminated or truncated
    assert len(asked) == decisions >= 5
    assert played == stepped


def test_the_strike_is_for_the_paddle_mode_only():
    with pytest.raises(ValueError, match="action_mode = 'pressure' is invalid: it corrects the paddle's"):
        PaddleStrike(gym.make("InflatedBall-v3"))
