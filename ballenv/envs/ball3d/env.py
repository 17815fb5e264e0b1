"""InflatedBall3D-v0: keep a 3-D inflated ball bouncing to a target height, and in paddle mode over
a target spot."""

from __future__ import annotations

import copy
from typing import TYPE_CHECKING, Any

import gymnasium as gym
import numpy as np
from gymnasium import Env, spaces
from gymnasium.utils import EzPickle
from numpy.typing import ArrayLike, NDArray

from ...extras import installed
from ..config import check_reset, parse_actions
from . import observation
from .ball import Ball
from .config import ENV_NAME, Ball3DConfig

if TYPE_CHECKING:
    from .render import Ball3DRenderer


def render_modes() -> list[str]:
    """The render modes this installation can draw in: rgb_array (NumPy only), human with pygame-ce."""
    return ["rgb_array", "human"] if installed("pygame") else ["rgb_array"]


class InflatedBall3DEnv(Env[NDArray[np.float32], NDArray[np.float32]], EzPickle):
    r"""
    ## Description
    A 3-D inflated ball (``ballenv.shell``: a discrete-shell skin of St. Venant-Kirchhoff triangles
    and bending hinges around a gas that follows the isothermal gas law ``(p + p_atm) V = const``)
    falls and bounces on a flat ground with Coulomb friction, simulated by implicit Newton steps
    with adaptive step size. Each episode draws a target apex height for the ball's centre of mass
    and, in paddle mode, a target spot on the floor. The agent keeps the ball bouncing to the height,
    either by pumping gas in and out (``action_mode="pressure"``) or by striking it from above with a
    paddle whose tilt steers it (``action_mode="paddle"``, like a hand dribbling toward a spot). The
    ball loses energy at every impact and to the skin's damping (``damping``), so an uncontrolled
    ball comes to rest within seconds.

    ## Action Space
    Pressure mode: ``Box(-1, 1, (1,), float32)``; paddle mode: ``Box(-1, 1, (3,), float32)``. Values
    outside are clipped; NaN raises ``ValueError``.

    | Mode     | Action | Sets                                                                  | Unit |
    |----------|--------|-----------------------------------------------------------------------|------|
    | pressure | a      | the gas amount, as the gauge pressure at rest p = p_lo + (a + 1)/2 (p_hi - p_lo) | Pa |
    | paddle   | a[0]   | the impulse J = (a[0] + 1)/2 * paddle_max_impulse of the next strike  | N s  |
    | paddle   | a[1:3] | the strike's tilt from straight down: paddle_max_tilt * min(1, |a[1:3]|) toward the azimuth atan2(a[2], a[1]) | rad |

    Pressure: the gas setpoint moves toward the command at most ``pressure_rate`` and the gas amount
    ramps to it over the control step; each simulator step holds the amount of its end time.
    Paddle: the paddle hovers over the ball at ``target + radius``; it strikes only a ball in flight
    (no ground contact since its lift-off) and falling, whose top is within ``paddle_reach`` of it,
    at most once per flight. A strike pushes the vertices within ``paddle_depth`` of the point the
    tilted paddle meets first, equally, over ``paddle_strike_duration``: the ball's momentum changes
    by exactly ``J d`` and its angular momentum by those forces' moment (``ballenv.envs.ball3d.task``).

    ## Observation Space
    ``Box(low, high, (7 V + 13,), float32)`` (``+ 7`` in paddle mode), V vertices (162 for the
    "fast" preset). Values are clipped to the bounds; ``env.unwrapped.observation_structure`` maps
    names to slices. The layout is declared once, in ``ballenv.envs.ball3d.observation``; this
    table repeats it.

    | Slice (name)             | Observation                                             | Unit | Bounds |
    |--------------------------|---------------------------------------------------------|------|--------|
    | vertex_position (3V)     | vertex x, y, z relative to the centre of mass           | m    | +-6 R |
    | vertex_velocity (3V)     | vertex velocity relative to the centre-of-mass velocity | m/s  | +-100 |
    | centre_of_mass_position  | x, y, and height above the ground                       | m    | arena |
    | centre_of_mass_velocity  | vx, vy, vz                                              | m/s  | +-100 |
    | ground_normal_force (V)  | each vertex's normal ground reaction (0 in flight)      | N    | [0, 1e5] |
    | pressure                 | gauge pressure of the gas now                           | Pa   | [-101325, 1e7] |
    | pressure_setpoint        | the gas amount as gauge pressure at the rest volume     | Pa   | pressure range |
    | target_height            | this episode's target apex height of the centre of mass | m    | target range |
    | last_apex                | height of the centre at its last flight apex (the start height before the first) | m | [-1, arena] |
    | target_spot (paddle)     | x, y of this episode's target spot                      | m    | arena |
    | paddle_height (paddle)   | the paddle's height                                     | m    | [0, arena + 6 R] |
    | paddle_in_reach (paddle) | 1 if the paddle can strike at the next step, else 0     | -    | [0, 1] |
    | paddle_impulse (paddle)  | impulse vector delivered in the last step               | N s  | +-J_max |

    ## Rewards
    Every step, in [0, 1]: DeepMind Control's gaussian tolerance ``exp(-(s e / m)^2 / 2)``,
    ``s = sqrt(2 ln 10)`` (1 on target, 0.1 at ``e = m``), of the relative error ``e = |h - h_target|
    / h_target`` of the apex the ball is headed for (``m = reward_margin``): while it rises in
    flight the centre's ballistic apex ``z + v_z^2 / (2 g)``; otherwise the last flight apex, capped
    by the height its free energy could still lift it. In paddle mode it is multiplied by the
    tolerance of the centre's horizontal distance to the target spot (``m = spot_margin``, m). 0 on a
    simulator failure. ``info`` has ``reward_height`` and ``reward_spot`` (1 in pressure mode).

    ## Starting State
    The ball, inflated to ``initial_pressure`` at its rest shape with a uniformly random rotation,
    centre over the origin at height ``U(start_height_range)``, horizontal velocity components
    ``U(-reset_noise_scale, reset_noise_scale)``; target apex ``U(target_height_range)``; target spot
    uniform in the disc of radius ``target_spot_radius`` about the origin.

    ## Episode End
    Terminated when the ball comes to rest (it could no longer rise ``rest_height``), leaves the
    arena (``|x|`` or ``|y| > arena_half_width``, or height above ``arena_height``), or the simulator
    fails (``info["sim_failure"]`` True, ``info["sim_failure_reason"]`` says why; the observation is
    the last accepted state, never NaN). Truncated by the time limit: ``max_episode_steps=1000``.

    ## Arguments
    ``gym.make("InflatedBall3D-v0", **kwargs)``; ``"InflatedBall3DPaddle-v0"`` is the same with
    ``action_mode="paddle"``.

    | Parameter              | Type  | Default       | Description |
    |------------------------|-------|---------------|-------------|
    | action_mode            | str   | "pressure"    | "pressure" or "paddle" |
    | fidelity               | str   | "fast"        | mesh and step control: "fast", "balanced", "accurate" (``ballenv.shell.presets``) |
    | control_frequency      | float | 100.0         | control steps per second (Hz) |
    | target_height_range    | tuple | (0.5, 1.0)    | target apex height of the centre (m) |
    | target_spot_radius     | float | 0.3           | the target spot is drawn in this disc (m) |
    | start_height_range     | tuple | (0.6, 1.2)    | initial height of the centre (m) |
    | pressure_range         | tuple | (20e3, 90e3)  | gauge pressure at rest for actions -1, +1 (Pa) |
    | initial_pressure       | float | 55e3          | gas at reset (and always, in paddle mode) (Pa) |
    | pressure_rate          | float | 4e5           | fastest change of the gas setpoint (Pa/s) |
    | paddle_max_impulse     | float | 1.5           | impulse of action +1 (N s) |
    | paddle_max_tilt        | float | 0.35          | largest tilt of a strike from straight down (rad) |
    | paddle_reach           | float | 0.4           | the paddle strikes when the ball's top is this close (m) |
    | paddle_depth           | float | 0.03          | it pushes the vertices this close to where it meets the ball (m) |
    | paddle_strike_duration | float | 3e-3          | a strike's duration, in (0, 1 / control_frequency] (s) |
    | radius                 | float | 0.12          | rest radius of the skin R (m) |
    | youngs_modulus         | float | 5e6           | skin modulus E (Pa) |
    | poisson_ratio          | float | 0.45          | skin Poisson ratio |
    | thickness              | float | 3e-3          | skin thickness h (m) |
    | density                | float | 1100.0        | skin density (kg/m^3) |
    | friction               | float | 0.5           | Coulomb coefficient of the ground |
    | damping                | float | 20.0          | damping of the skin's deformation c (1/s) |
    | gravity                | float | 9.81          | g (m/s^2) |
    | reward_margin          | float | 0.5           | relative apex error at which the height term is 0.1 |
    | spot_margin            | float | 0.3           | distance to the spot at which the spot term is 0.1 (m) |
    | reset_noise_scale      | float | 0.05          | horizontal start speed range (m/s) |
    | arena_half_width       | float | 2.0           | (m) |
    | arena_height           | float | 5.0           | (m) |
    | rest_height            | float | 0.01          | the ball is at rest when it could rise no more (m) |
    | render_mode            | str   | None          | "human" or "rgb_array"; one frame per control step, ``render_fps`` = control_frequency |

    ## Version History
    - v0: initial release.
    """

    metadata = {"render_modes": render_modes(), "render_fps": 100.0}  # control_frequency

    def __init__(self, render_mode: str | None = None, **kwargs: Any) -> None:
        EzPickle.__init__(self, render_mode=render_mode, **kwargs)
        self.config = Ball3DConfig.from_kwargs(kwargs)
        if render_mode not in (None, "human", "rgb_array"):
            raise ValueError(
                f"{ENV_NAME}.render_mode = {render_mode!r} is out of range: must be None, 'human' or "
                "'rgb_array'"
            )
        self.render_mode = render_mode
        low, high = observation.bounds(self.config)
        self.observation_space = spaces.Box(low, high, dtype=np.float32)
        n_actions = 3 if self.config.paddle else 1
        self.action_space = spaces.Box(-1.0, 1.0, shape=(n_actions,), dtype=np.float32)
        self._structure = observation.structure(self.config.n_vertices, self.config.paddle)
        self.ball = Ball(self.config)
        self._renderer: Ball3DRenderer | None = None
        if render_mode == "human":
            from .render import Ball3DRenderer

            Ball3DRenderer(self.config, "human", 1.0)  # what to install, now rather than at the first frame
        self._has_reset = False
        self.metadata = {**self.metadata, "render_fps": self.config.control_frequency}

    @property
    def observation_structure(self) -> dict[str, slice]:
        """Name -> slice of the observation vector (a new dict)."""
        return dict(self._structure)

    @property
    def dt(self) -> float:
        """Control step (s)."""
        return self.config.control_dt

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[NDArray[np.float32], dict[str, Any]]:
        super().reset(seed=seed)
        self.ball.reset(self.np_random)
        self._has_reset = True
        if self.render_mode == "human":
            self.render()
        return self.ball.observe(), self.ball.info()

    def step(self, action: ArrayLike) -> tuple[NDArray[np.float32], float, bool, bool, dict[str, Any]]:
        check_reset(self._has_reset, "step", ENV_NAME)
        n = 3 if self.config.paddle else 1
        a = np.clip(parse_actions(action, n, "step action", ENV_NAME), -1.0, 1.0)
        self.ball.act(a)
        if self.render_mode == "human":
            self.render()
        return self.ball.observe(), self.ball.reward[0], self.ball.end != "", False, self.ball.info()

    def __deepcopy__(self, memo: dict[int, Any]) -> InflatedBall3DEnv:
        """A copy in the same episode, stepping exactly as this env would (the renderer is not copied)."""
        kwargs: dict[str, Any] = dict(self._ezpickle_kwargs)
        other = type(self)(**kwargs)
        other.ball = copy.deepcopy(self.ball, memo)
        other._has_reset = self._has_reset
        other._np_random = copy.deepcopy(self._np_random, memo)
        other._np_random_seed = self._np_random_seed
        return other

    def render(self) -> NDArray[np.uint8] | None:
        if self.render_mode is None:
            return None
        check_reset(self._has_reset, "render", ENV_NAME)
        if self._renderer is None:
            from .render import Ball3DRenderer

            self._renderer = Ball3DRenderer(self.config, self.render_mode, self.metadata["render_fps"])
        return self._renderer.render(self.ball)

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None


def ball3d_env(env: gym.Env[Any, Any]) -> InflatedBall3DEnv:
    """The InflatedBall3D env under ``env``'s wrappers (TypeError for any other env)."""
    ball = env.unwrapped
    if not isinstance(ball, InflatedBall3DEnv):
        raise TypeError(f"{env} is not an InflatedBall3D env: {ENV_NAME} or InflatedBall3DPaddle-v0 expected")
    return ball
