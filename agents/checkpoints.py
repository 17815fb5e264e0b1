"""A run's resumable state: what an interrupted training goes on from.

``RUN/resume/`` holds the model as it is (``model.zip``), the whole observation and return
normalisation (``vecnormalize.pkl``, the ``VecNormalize`` Stable-Baselines3 pickles, without its
envs) and ``state.json`` (the env steps done). Each is written atomically and signed
(:mod:`agents.signatures`), so that ``train.py --resume RUN`` loads only what this user's training
wrote. Training saves it every ``--checkpoint-minutes`` minutes (:func:`every`) and when it is
interrupted: the first Ctrl-C asks the training to stop after the step under way (:class:`CtrlC`),
so that no file is cut in the middle of being written; a second one interrupts at once.
"""

from __future__ import annotations

import json
import pathlib
import pickle
import signal
import threading
import time
from typing import Any

from ballenv.files import atomic_path, write_text

from .signatures import require_signed, sign

RESUME = "resume"


def save(run: pathlib.Path, model: Any, envs: Any) -> pathlib.Path:
    """Write ``model`` and the normalisation of ``envs`` (if it normalises) into ``run/resume``."""
    folder = run / RESUME
    folder.mkdir(exist_ok=True)
    with atomic_path(folder / "model.zip") as tmp:
        model.save(tmp)
    written = [folder / "model.zip"]
    if hasattr(envs, "obs_rms"):  # a VecNormalize
        with atomic_path(folder / "vecnormalize.pkl") as tmp:
            envs.save(str(tmp))
        written.append(folder / "vecnormalize.pkl")
    written.append(write_text(folder / "state.json", json.dumps({"num_timesteps": int(model.num_timesteps)})))
    sign(written)
    return folder


def steps_done(run: pathlib.Path) -> int:
    """The env steps the saved state of ``run`` had taken (ValueError if there is none)."""
    path = run / RESUME / "state.json"
    if not path.exists():
        raise ValueError(f"{run} has no resumable state ({path} is missing): nothing to resume")
    require_signed(path, trust=False)
    return int(json.loads(path.read_text())["num_timesteps"])


def load(run: pathlib.Path, cls: Any, envs: Any) -> Any:
    """The saved model of ``run`` bound to ``envs``, whose normalisation is restored from the saved
    one; both must carry this user's signature."""
    folder = run / RESUME
    require_signed(folder / "model.zip", trust=False)
    model = cls.load(folder / "model.zip", env=envs, device="cpu")
    if hasattr(envs, "obs_rms"):
        require_signed(folder / "vecnormalize.pkl", trust=False)
        with open(folder / "vecnormalize.pkl", "rb") as f:
            saved = pickle.load(f)  # noqa: S301 - signed by this user's training
        envs.obs_rms, envs.ret_rms = saved.obs_rms, saved.ret_rms
    return model


def every(run: pathlib.Path, minutes: float) -> Any:
    """A callback that saves the resumable state every ``minutes`` of training (0: never)."""
    from stable_baselines3.common.callbacks import BaseCallback

    class Every(BaseCallback):
        def _on_training_start(self) -> None:
            self.last = time.monotonic()

        def _on_step(self) -> bool:
            if minutes > 0 and time.monotonic() - self.last >= 60.0 * minutes:
                save(run, self.model, self.model.get_env())
                self.last = time.monotonic()
            return True

    return Every()


class CtrlC:
    """While the block runs (``with CtrlC() as stop``), the first SIGINT sets ``stop.requested``
    instead of raising; :meth:`callback` stops the training at its next step then. A second SIGINT
    raises KeyboardInterrupt at once. Outside the main thread (a Ray worker) it changes nothing."""

    def __init__(self) -> None:
        self.requested = False
        self.previous: Any = None

    def __enter__(self) -> CtrlC:
        if threading.current_thread() is threading.main_thread():
            self.previous = signal.signal(signal.SIGINT, self._first)
        return self

    def _first(self, signum: int, frame: Any) -> None:
        self.requested = True
        signal.signal(signal.SIGINT, signal.default_int_handler)

    def __exit__(self, *exc: object) -> None:
        if self.previous is not None:
            signal.signal(signal.SIGINT, self.previous)

    def callback(self) -> Any:
        """A callback that ends the training once a stop is requested."""
        from stable_baselines3.common.callbacks import BaseCallback

        stop = self

        class Stop(BaseCallback):
            def _on_step(self) -> bool:
                return not stop.requested

        return Stop()
