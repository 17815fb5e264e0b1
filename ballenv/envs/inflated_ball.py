"""InflatedBall-v3: keep an inflated elastic ball bouncing to a target apex height."""

from __future__ import annotations

import copy
from typing import TYPE_CHECKING, Any

import gymnasium as gym
import numpy as np
from gymnasium import Env, spaces
from gymnasium.utils import EzPickle
from numpy.typing import ArrayLike, NDArray

from ..extras import RENDER_NEEDS, render_modes, require_render_mode
from ..physics.base.ring import total_mass
from .batch import BallBatch, observation_structure
from .config import BallEnvConfig, check_reset, draw_reset, failure_message, parse_actions
from .task import END_REASONS, REWARD, REWARD_TERMS, REWARD_TOTAL

if TYPE_CHECKING:
    from .render import BallRenderer


class InflatedBallEnv(Env[NDArray[np.float32], NDArray[np.float32]], EzPickle):
    r"""
    ## Description
    A 2-D inflated ring (discrete elastic rods: stretching and bending of the wall, gas that follows
    the isothermal gas law ``(p + p_atm) A = const``) falls and bounces on a flat ground with Coulomb
    friction, simulated by implicit Newton steps with adaptive step size (see ``ballenv.physics``).
    Each episode draws a target apex height for the ball's centre of mass; the agent keeps the ball
    bouncing to it, either by pumping gas in and out (``action_mode="pressure"``) or by striking the
    ball from above with a paddle, like a hand dribbling (``action_mode="paddle"``). The ball loses
    energy at every impact (and to the wall's damping, ``damping``), so an uncontrolled ball comes to
    rest within a few seconds.

    ## Action Space
    ``Box(-1, 1, (1,), float32)``; values outside are clipped, NaN raises ``ValueError``.

    | Mode     | Action a in [-1, 1] sets                                                     | Unit  |
    |----------|------------------------------------------------------------------------------|-------|
    | pressure | the gas amount, as the gauge pressure at rest p = p_lo + (a + 1)/2 (p_hi - p_lo) | Pa |
    | paddle   | the downward impulse J = (a + 1)/2 * paddle_max_impulse of the next strike    | N s |

    Pressure: the gas setpoint moves toward the commanded value at most ``pressure_rate`` (a pump's
    flow; instant jumps of the gas ring the ball's breathing mode like a bell), and the gas amount
    follows it as a ramp: linear in time over the control step, from the amount held at its start
    to the setpoint's at its end (each simulator step holds the amount of its own time); the gas
    law then sets the pressure as the ball deforms, so raising it while the ball is squashed does
    work ``p dA`` as it re-expands.
    Paddle: the paddle hovers at ``target + r`` (where the ball's top is at the target apex); it
    strikes only a ball in flight (no ground contact since its lift-off) and falling (centre of
    mass moving down) whose top is within ``paddle_reach`` of it, at most once per flight (a
    second strike waits for the next flight), as a dribbling hand meets the ball coming down, and then shares ``J`` equally among the nodes
    within ``paddle_depth`` of the top when it strikes, delivered at a constant rate over
    ``paddle_strike_duration``: the ball's momentum changes by exactly J. Action -1 lets the ball
    pass unstruck (it may still be struck later in the same flight).

    ## Observation Space
    ``Box(low, high, (5 N + 8,), float32)`` (``+3`` in paddle mode), N nodes (32 for the "fast"
    preset). Values are clipped to the bounds; ``env.unwrapped.observation_structure`` maps names to
    slices. The layout is declared once, in ``ballenv.envs.observation``; this table repeats it.

    | Slice (name)             | Observation                                             | Unit | Bounds |
    |--------------------------|---------------------------------------------------------|------|--------|
    | node_position (2N)       | node x, y relative to the centre of mass, interleaved   | m    | +-4 r_max |
    | node_velocity (2N)       | node velocity relative to the centre-of-mass velocity   | m/s  | +-100 |
    | centre_of_mass_position  | x, and height above the ground                          | m    | arena |
    | centre_of_mass_velocity  | vx, vy                                                  | m/s  | +-100 |
    | ground_normal_force (N)  | each node's normal ground reaction (0 in flight)        | N    | [0, 1e5] |
    | pressure                 | current gauge pressure of the gas                       | Pa   | [-101325, 1e7] |
    | pressure_setpoint        | the gas amount as gauge pressure at rest (moves toward the command) | Pa | pressure range |
    | target_height            | this episode's target apex height of the centre of mass | m    | target range |
    | last_apex                | height of the centre at its last flight apex (the start height before the first) | m | [-1, arena] |
    | paddle_height (paddle)   | the paddle's height                                     | m    | [0, arena + 4 r_max] |
    | paddle_in_reach (paddle) | 1 if the paddle can strike at the next step, else 0 (a falling ball in flight, once per flight) | - | [0, 1] |
    | paddle_impulse (paddle)  | impulse delivered at the last step                      | N s  | [0, J_max] |

    ## Rewards
    Every step, in [0, 1] (also ``info["reward_height"]``): how close the apex the ball is headed for
    is to the target, ``exp(-(s e / reward_margin)^2 / 2)`` with ``e = |h - h_target| / h_target``
    and ``s = sqrt(2 ln 10)`` (DeepMind Control's gaussian ``tolerance``: 1 on target, 0.1 at
    ``e = reward_margin``). ``h`` is, while the ball rises in flight, the centre of mass's ballistic
    apex ``y + v_y^2 / (2 g)`` (exact: only gravity acts on the centre); otherwise (falling, or in
    contact) the last flight apex (``last_apex``), capped by the height the free energy (kinetic,
    elastic and gas energy above the inflated circle at rest) could lift the centre to. Energy a
    bounce loses lowers ``h`` at once; energy put in by a strike or the pump counts from the lift-off
    it leads to, so the reward ranks policies as the apex error does (a reward of the energy alone
    would favour paddle strikes too weak to make up the bounce's loss). 0 on a simulator failure.
    All rewards are >= 0, so ending an episode early forfeits the rest: staying in play pays, and no
    number of bounces is favoured (the reward counts time, not apexes). The task's measure is the
    flight apexes' error (``info["apex_height"]``, ``agents.evaluate``).

    ## Starting State
    The ball, inflated to ``initial_pressure``, at rest shape with a random rotation, centre at
    height ``U(start_height_range)``, horizontal velocity ``U(-reset_noise_scale, reset_noise_scale)``,
    no vertical velocity; target apex ``U(target_height_range)``.

    ## Episode End
    Terminated when the ball comes to rest (it could no longer rise ``rest_height``), leaves the
    arena (``|x| > arena_half_width`` or height above ``arena_height``), or the simulator fails
    (``info["sim_failure"]`` True, ``info["sim_failure_reason"]`` says why; the observation is the
    last accepted state, never NaN). Truncated by the time limit only: ``max_episode_steps=1000``
    (10 s at 100 Hz).

    ## Arguments
    ``gym.make("InflatedBall-v3", **kwargs)`` (or ``"ballenv:InflatedBall-v3"``, which also works in
    spawned subprocesses).

    | Parameter                   | Type  | Default        | Description |
    |-----------------------------|-------|----------------|-------------|
    | action_mode                 | str   | "pressure"     | "pressure" or "paddle" |
    | fidelity                    | str   | "fast"         | node count and step control: "fast", "balanced", "accurate" (`ballenv.envs.numerics`) |
    | control_frequency           | float | 100.0          | control steps per second (Hz) |
    | target_height_range         | tuple | (0.5, 1.0)     | target apex height of the centre (m) |
    | start_height_range          | tuple | (0.6, 1.2)     | initial height of the centre (m) |
    | pressure_range              | tuple | (10e3, 50e3)   | gauge pressure at rest for actions -1, +1 (Pa) |
    | initial_pressure            | float | 30e3           | gas at reset (and always, in paddle mode) (Pa) |
    | pressure_rate               | float | 4e5            | fastest change of the gas setpoint (Pa/s) |
    | paddle_max_impulse          | float | 0.15           | impulse of action +1 (N s) |
    | paddle_reach                | float | 0.4            | paddle strikes when the ball's top is this close (m) |
    | paddle_depth                | float | 0.06           | it touches the nodes this close to the top (m) |
    | paddle_strike_duration      | float | 3e-3           | a strike delivers its impulse over this time, in (0, 1 / control_frequency] (s) in paddle mode, (0, 1] in pressure mode |
    | radius                      | float | 0.12           | unstretched ring radius R (m) |
    | youngs_modulus              | float | 10e6           | wall modulus E (Pa) |
    | thickness                   | float | 2e-3           | wall thickness h (m) |
    | width                       | float | 0.02           | out-of-plane width b (m) |
    | density                     | float | 1100.0         | wall density (kg/m^3) |
    | friction                    | float | 0.5            | Coulomb coefficient of the ground |
    | damping                     | float | 20.0           | the wall's damping of deformation c (1/s) |
    | gravity                     | float | 9.81           | g (m/s^2) |
    | reward_margin               | float | 0.5            | relative apex error at which the reward is 0.1 |
    | reset_noise_scale           | float | 0.05           | horizontal start speed range (m/s) |
    | arena_half_width            | float | 3.0            | (m) |
    | arena_height                | float | 5.0            | (m) |
    | rest_height                 | float | 0.01           | the ball is at rest when it could rise no more (m) |
    | render_mode                 | str   | None           | "human" or "rgb_array"; one frame per control step, ``metadata["render_fps"]`` = control_frequency (real time) |

    ## Vector Environments
    ``gym.make_vec("InflatedBall-v3", num_envs=n, **kwargs)`` builds the native vector env by default
    (``vectorization_mode="vector_entry_point"``: every ball stepped in one compiled call, on
    ``num_threads`` threads; its options are in ``ballenv.envs.vector``). Gymnasium passes it no
    ``wrappers`` and no ``vector_kwargs``: with either, ask for ``vectorization_mode="sync"`` (or
    ``"async"``), which steps these same single envs one after the other.

    ## Version History
    - v3: the paddle strikes only a ball in flight, not one squashing on the ground (paddle dynamics; the observation, the reward and the pressure mode are as in v2). v2 is no longer registered.
    - v2: smooth actuation: the gas amount ramps to its setpoint over the control step and a strike delivers its impulse over ``paddle_strike_duration`` (new keyword), both stepped by the simulator. v1 is no longer registered.
    - v1: generalized-alpha presets with ``rho_infinity = 0.3`` and actions that keep the integrator's carried acceleration; a per-step tolerance reward of the apex the ball is headed for (``reward_margin`` replaces the v0 reward weights); the observation gains ``pressure_setpoint`` and ``last_apex``; the paddle strikes a falling ball once per flight. v0 is no longer registered.
    - v0: initial release.
    """

    # the modes this installation can draw in (Pillow; pygame-ce for "human"): what checkers try
    metadata = {"render_modes": render_modes(), "render_fps": 100.0}  # control_frequency

    def __init__(self, render_mode: str | None = None, **kwargs: Any) -> None:
        EzPickle.__init__(self, render_mode=render_mode, **kwargs)
        self.config = BallEnvConfig.from_kwargs(kwargs)
        if render_mode is not None and render_mode not in RENDER_NEEDS:
            raise ValueError(
                f"InflatedBall-v3.render_mode = {render_mode!r} is out of range: must be None, "
                "'human' or 'rgb_array'"
            )
        if render_mode is not None:
            require_render_mode(render_mode)  # what to install, now rather than at the first frame
        self.render_mode = render_mode
        low, high = self.config.observation_bounds()
        self._batch = BallBatch(self.config.scene(), 1, self.config.task_settings(), low, high)
        self.observation_space = spaces.Box(low, high, dtype=np.float32)
        self.action_space = spaces.Box(-1.0, 1.0, shape=(1,), dtype=np.float32)
        self._observation_structure = observation_structure(self.config.n_nodes, self.config.mode)
        self._actions = np.zeros(1)
        self._renderer: BallRenderer | None = None
        self._has_reset = False
        # one frame per control step: videos (RecordVideo) and the window play in real time
        self.metadata = {**self.metadata, "render_fps": self.config.control_frequency}

    @property
    def observation_structure(self) -> dict[str, slice]:
        """Name -> slice of the observation vector (a new dict: the caller may change it)."""
        return dict(self._observation_structure)

    @property
    def dt(self) -> float:
        """Control step (s)."""
        return self.config.control_dt

    @property
    def ball_mass(self) -> float:
        """Mass of the ball (kg): its ring's wall, ``rho b h`` times its rest length."""
        return total_mass(self.config.ring(self.config.initial_pressure))

    @property
    def apexes_last_step(self) -> int:
        """Flight apexes the ball passed in the last control step (``info["apex_count"]``)."""
        return int(self._batch.task.apex_count[0])

    def planning_copies(self, n: int) -> BallBatch:
        """``n`` copies of this env's ball for planning: a :class:`~ballenv.envs.batch.BallBatch` of
        the same scene and task settings. Set them to this env's state with :meth:`copy_state_to`,
        try actions with ``BallBatch.step(actions, running)`` and read ``BallBatch.task`` and
        ``BallBatch.obs``."""
        low, high = self.config.observation_bounds()
        return BallBatch(self.config.scene(), n, self.config.task_settings(), low, high)

    def copy_state_to(self, copies: BallBatch, rows: ArrayLike) -> None:
        """Set envs ``rows`` of ``copies`` (:meth:`planning_copies`) to this env's simulator and task
        state: from here each steps exactly as this env would, to the bit."""
        copies.copy_env(self._batch, 0, rows)

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[NDArray[np.float32], dict[str, Any]]:
        super().reset(seed=seed)
        centre, velocity, phase, target = draw_reset(self.config, self.np_random)
        self._batch.reset(0, centre, velocity, phase, target, self.config.initial_pressure)
        self._has_reset = True
        if self.render_mode == "human":
            self.render()
        info = {"target_height": float(target), "time": 0.0}
        return self._batch.obs[0].copy(), info

    def step(self, action: ArrayLike) -> tuple[NDArray[np.float32], float, bool, bool, dict[str, Any]]:
        check_reset(self._has_reset, "step")
        a = parse_actions(action, 1, "step action")
        self._actions[0] = min(1.0, max(-1.0, a[0]))
        batch = self._batch
        batch.step(self._actions)
        task = batch.task
        end = int(task.end[0])
        if self.render_mode == "human":
            self.render()
        return batch.obs[0].copy(), float(task.reward[0, REWARD_TOTAL]), end != 0, False, self._step_info()

    def _step_info(self) -> dict[str, Any]:
        task = self._batch.task
        info: dict[str, Any] = {name: float(task.reward[0, REWARD.index(name)]) for name in REWARD_TERMS}
        reason = END_REASONS[int(task.end[0])]
        info.update(
            time=float(task.steps[0] * self.config.control_dt),
            apex_count=int(task.apex_count[0]),
            apex_height=float(task.apex_height[0]),
            target_height=float(task.target[0]),
            pressure_setpoint=float(task.setpoint[0]),
            paddle_impulse=float(task.impulse[0]),
            termination=reason,
            sim_failure=reason == "sim_failure",
            sim_failure_reason=failure_message(task, 0),
        )
        return info

    def __deepcopy__(self, memo: dict[int, Any]) -> InflatedBallEnv:
        """A copy in the same episode: the same settings, and the simulator's, the task's and the
        random generator's state copied, so it steps exactly as this env would (a renderer is not
        copied; the copy makes its own when it draws)."""
        kwargs: dict[str, Any] = dict(self._ezpickle_kwargs)
        other = type(self)(**kwargs)  # EzPickle keeps the keywords it was made with
        other._batch.copy_env(self._batch, 0, np.zeros(1, dtype=np.int64))
        other._actions[:] = self._actions
        other._has_reset = self._has_reset
        other._np_random = copy.deepcopy(self._np_random, memo)
        other._np_random_seed = self._np_random_seed
        return other

    def render(self) -> NDArray[np.uint8] | None:
        if self.render_mode is None:
            return None
        check_reset(self._has_reset, "render")
        if self._renderer is None:
            from .render import BallRenderer

            self._renderer = BallRenderer(self.config, self.render_mode, self.metadata["render_fps"])
        return self._renderer.render(self._batch, 0)

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None


def ball_env(env: gym.Env[Any, Any]) -> InflatedBallEnv:
    """The InflatedBall env under ``env``'s wrappers (TypeError for any other env)."""
    ball = env.unwrapped
    if not isinstance(ball, InflatedBallEnv):
        raise TypeError(
            f"{env} is not an InflatedBall env: InflatedBall-v3 (or InflatedBallPaddle-v3) expected"
        )
    return ball
