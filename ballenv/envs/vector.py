"""A native vector env of InflatedBall-v3: all balls stepped in one compiled call.

``gym.make_vec("InflatedBall-v3", num_envs=64, vectorization_mode="vector_entry_point", **kwargs)``.
Env ``i`` uses the random stream of a single env reset with ``seed + i`` (as ``SyncVectorEnv``
seeds its envs) and the same compiled step, so it reproduces single envs exactly. Autoreset follows
Gymnasium's default ``NEXT_STEP`` mode: the step after an episode ends resets that env, ignores its
action and returns the first observation of the new episode with reward 0. Its options, and what
to ask ``gym.make_vec`` for to wrap each env: :class:`InflatedBallVectorEnv`.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numba
import numpy as np
from gymnasium import spaces
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space
from numpy.typing import ArrayLike, NDArray

from ..extras import render_modes
from .batch import BallBatch, observation_structure
from .config import BallEnvConfig, check_reset, draw_reset, failure_message, parse_actions
from .inflated_ball import InflatedBallEnv
from .task import END_FAILURE, END_REASONS, REWARD, REWARD_TERMS, REWARD_TOTAL

if TYPE_CHECKING:
    from .render import BallRenderer

DEFAULT_MAX_EPISODE_STEPS = 1000
VECTORISER_KEYWORDS = {"wrappers", "vector_kwargs"}  # gym.make_vec's, for sync and async only


class InflatedBallVectorEnv(VectorEnv[NDArray[np.float32], NDArray[np.float32], NDArray[Any]]):
    """``num_envs`` InflatedBall-v3 episodes advanced together (see :class:`InflatedBallEnv` for the
    task, spaces and keyword arguments; ``max_episode_steps`` truncates each episode).

    ``num_threads`` (default: numba's thread count, the machine's cores, at most ``num_envs``) steps
    the envs on that many threads in one compiled call; every env's numbers are those of a single
    env, to the bit, whatever the thread count.

    ## Options
    ``gym.make_vec`` passes its keyword arguments to :class:`InflatedBallVectorEnv`:

    | Keyword | Default | Description |
    |---|---|---|
    | num_envs | 1 | envs stepped together (int in [1, 100000]) |
    | max_episode_steps | 1000 (the id's) | control steps after which an env's episode is truncated |
    | num_threads | the cores, at most num_envs | threads stepping the envs in one call (same numbers) |
    | render_mode | None | None or "rgb_array": a tuple of one frame per env (Pillow) |
    | the env's keywords | as InflatedBall-v3 | ``action_mode``, ``fidelity``, ...: the same for every env |

    ## Wrappers and vector_kwargs
    The native vector env is ``gym.make_vec``'s default for these ids (they register a vector
    entry point, as Gymnasium's CartPole does). Gymnasium gives a vector entry point neither
    per-env ``wrappers`` nor ``vector_kwargs``: it refuses both before the env is built
    (``gymnasium.error.Error: Cannot use `vector_entry_point` vectorization mode with the wrappers
    argument``, or ``... `vector_kwargs` is not empty``). For wrappers around each env, or a
    vectoriser's options (``autoreset_mode``, ``context``, ``shared_memory``, ...), ask for
    Gymnasium's own vectorisation: ``gym.make_vec("InflatedBall-v3", num_envs=2,
    vectorization_mode="sync", wrappers=[...], vector_kwargs={...})`` (``"async"``: one process
    per env, ``"ballenv:InflatedBall-v3"`` in spawned processes). Its envs are the same single
    envs, so the numbers are the native env's. The constructor itself refuses ``wrappers`` and
    ``vector_kwargs`` with the same advice.
    """

    metadata = {
        "render_modes": [m for m in render_modes() if m == "rgb_array"],  # Pillow installed
        "render_fps": 100.0,  # control_frequency (set per instance)
        "autoreset_mode": AutoresetMode.NEXT_STEP,
    }

    def __init__(
        self,
        num_envs: int = 1,
        max_episode_steps: int = DEFAULT_MAX_EPISODE_STEPS,
        render_mode: str | None = None,
        num_threads: int | None = None,
        **kwargs: Any,
    ) -> None:
        stray = sorted(VECTORISER_KEYWORDS & set(kwargs))
        if stray:
            raise TypeError(
                f"InflatedBall-v3's native vector env takes no {stray[0]!r}: ask gym.make_vec for "
                f'vectorization_mode="sync" (or "async") to wrap each env or to set the vectoriser\'s '
                "options"
            )
        if isinstance(num_envs, bool) or not isinstance(num_envs, int) or not 1 <= num_envs <= 100_000:
            raise ValueError(
                f"InflatedBall-v3.num_envs = {num_envs!r} is out of range: must be an integer in [1, 100000]"
            )
        if (
            isinstance(max_episode_steps, bool)
            or not isinstance(max_episode_steps, int)
            or max_episode_steps < 1
        ):
            raise ValueError(
                f"InflatedBall-v3.max_episode_steps = {max_episode_steps!r} is out of range: must be an "
                "integer >= 1"
            )
        if render_mode not in (None, "rgb_array"):
            raise ValueError(
                f"InflatedBall-v3 vector render_mode = {render_mode!r} is out of range: must be None "
                "or 'rgb_array'"
            )
        # numba sets its config's values at import: its type stubs do not declare them
        most = numba.config.NUMBA_NUM_THREADS  # type: ignore[attr-defined]
        if num_threads is None:
            num_threads = min(numba.get_num_threads(), num_envs)
        if isinstance(num_threads, bool) or not isinstance(num_threads, int) or not 1 <= num_threads <= most:
            raise ValueError(
                f"InflatedBall-v3.num_threads = {num_threads!r} is out of range: must be an integer in "
                f"[1, {most}] (numba's NUMBA_NUM_THREADS)"
            )
        self.config = BallEnvConfig.from_kwargs(kwargs)
        self.num_envs = num_envs
        self.max_episode_steps = max_episode_steps
        self.render_mode = render_mode
        low, high = self.config.observation_bounds()
        self._batch = BallBatch(
            self.config.scene(), num_envs, self.config.task_settings(), low, high, threads=num_threads
        )
        self.single_observation_space = spaces.Box(low, high, dtype=np.float32)
        self.single_action_space = spaces.Box(-1.0, 1.0, shape=(1,), dtype=np.float32)
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)
        self._observation_structure = observation_structure(self.config.n_nodes, self.config.mode)
        self._rngs = [seeding.np_random()[0] for _ in range(num_envs)]
        self._autoreset = np.zeros(num_envs, dtype=np.bool_)
        self._actions = np.zeros(num_envs)
        self._renderer: BallRenderer | None = None
        self._has_reset = False
        self.metadata = {**self.metadata, "render_fps": self.config.control_frequency}

    @property
    def observation_structure(self) -> dict[str, slice]:
        """Name -> slice of each env's observation vector (a new dict: the caller may change it)."""
        return dict(self._observation_structure)

    def reset(
        self, *, seed: int | Sequence[int | None] | None = None, options: dict[str, Any] | None = None
    ) -> tuple[NDArray[np.float32], dict[str, Any]]:
        super().reset(seed=seed if isinstance(seed, int) else None)  # its generator takes an int only
        seeds: list[int | None]
        if seed is None:
            seeds = [None] * self.num_envs
        elif isinstance(seed, int):
            seeds = [seed + i for i in range(self.num_envs)]
        else:
            seeds = list(seed)
            if len(seeds) != self.num_envs:
                raise ValueError(
                    f"InflatedBall-v3 vector reset seed has {len(seeds)} entries: must have "
                    f"num_envs = {self.num_envs}"
                )
        for i, s in enumerate(seeds):
            self._rngs[i], _ = seeding.np_random(s)
            self._reset_env(i)
        self._autoreset[:] = False
        self._has_reset = True
        info = {"target_height": self._batch.task.target.copy(), "time": np.zeros(self.num_envs)}
        return self._batch.obs.copy(), info

    def _reset_env(self, i: int) -> None:
        centre, velocity, phase, target = draw_reset(self.config, self._rngs[i])
        self._batch.reset(i, centre, velocity, phase, target, self.config.initial_pressure)

    def step(
        self, actions: ArrayLike
    ) -> tuple[
        NDArray[np.float32], NDArray[np.float64], NDArray[np.bool_], NDArray[np.bool_], dict[str, Any]
    ]:
        check_reset(self._has_reset, "vector step")
        a = parse_actions(actions, self.num_envs, "vector step actions")
        np.clip(a, -1.0, 1.0, out=self._actions)
        resetting = self._autoreset.copy()
        batch = self._batch
        batch.step(self._actions, ~resetting)
        for i in np.flatnonzero(resetting):
            self._reset_env(int(i))
        task = batch.task
        stepped = ~resetting
        terminated = (task.end != 0) & stepped
        truncated = (task.steps >= self.max_episode_steps) & stepped
        reward = np.where(stepped, task.reward[:, REWARD_TOTAL], 0.0)
        self._autoreset = terminated | truncated
        return batch.obs.copy(), reward, terminated, truncated, self._step_info(stepped)

    def _step_info(self, stepped: NDArray[np.bool_]) -> dict[str, Any]:
        task = self._batch.task
        info = {name: np.where(stepped, task.reward[:, REWARD.index(name)], 0.0) for name in REWARD_TERMS}
        reasons = np.where(stepped, np.array(END_REASONS, dtype=object)[task.end], "")
        failures = np.full(self.num_envs, "", dtype=object)
        for i in np.flatnonzero(stepped & (task.end == END_FAILURE)):
            failures[i] = failure_message(task, int(i))
        info.update(
            time=task.steps * self.config.control_dt,
            apex_count=np.where(stepped, task.apex_count, 0),
            apex_height=np.where(stepped, task.apex_height, 0.0),
            target_height=task.target.copy(),
            pressure_setpoint=task.setpoint.copy(),
            paddle_impulse=np.where(stepped, task.impulse, 0.0),
            termination=reasons,
            sim_failure=reasons == "sim_failure",
            sim_failure_reason=failures,
        )
        return info

    def render(self) -> tuple[NDArray[np.uint8], ...] | None:
        if self.render_mode is None:
            return None
        check_reset(self._has_reset, "vector render")
        if self._renderer is None:
            from .render import BallRenderer

            self._renderer = BallRenderer(self.config, "rgb_array", self.metadata["render_fps"])
        frames = (self._renderer.render(self._batch, i) for i in range(self.num_envs))
        return tuple(frame for frame in frames if frame is not None)  # rgb_array: one per env

    def close_extras(self, **kwargs: Any) -> None:
        self._batch.close()
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None


__all__ = ["InflatedBallEnv", "InflatedBallVectorEnv"]
