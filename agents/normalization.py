"""The observation normalisation a run trained behind, saved as plain data (no pickle).

Stable-Baselines3's ``VecNormalize`` scales each observation entry by its running mean and
variance, ``clip((obs - mean) / sqrt(var + epsilon), -clip_obs, clip_obs)``; a run folder keeps
those statistics (``vecnormalize.npz``, ``best_vecnormalize.npz``: ``mean``, ``var``, ``count``,
``clip_obs``, ``epsilon``, ``norm_obs``), and evaluation applies them frozen.
"""

from __future__ import annotations

import pathlib
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from ballenv.files import atomic_path


class Normalization(NamedTuple):
    """Frozen observation statistics: per-entry ``mean`` and ``var``, ``clip`` and ``epsilon``."""

    mean: NDArray[np.float64]
    var: NDArray[np.float64]
    clip: float
    epsilon: float

    def apply(self, obs: NDArray[Any]) -> NDArray[np.float32]:
        """``obs`` normalised as ``VecNormalize.normalize_obs`` does, as float32."""
        scaled = np.clip((obs - self.mean) / np.sqrt(self.var + self.epsilon), -self.clip, self.clip)
        return scaled.astype(np.float32)


def save(vec_normalize: Any, path: pathlib.Path) -> pathlib.Path:
    """Write the observation statistics of a ``VecNormalize`` to ``path`` (npz, atomically)."""
    rms = vec_normalize.obs_rms
    with atomic_path(path) as tmp, open(tmp, "wb") as f:
        np.savez(
            f, mean=np.asarray(rms.mean, dtype=float), var=np.asarray(rms.var, dtype=float),
            count=np.float64(rms.count), clip_obs=np.float64(vec_normalize.clip_obs),
            epsilon=np.float64(vec_normalize.epsilon), norm_obs=np.bool_(vec_normalize.norm_obs),
        )  # fmt: skip
    return pathlib.Path(path)


def load(path: pathlib.Path) -> Normalization | None:
    """The statistics saved at ``path`` (None if the run did not normalise its observations);
    ValueError naming the file if it is not such a file."""
    try:
        with np.load(path, allow_pickle=False) as data:
            if not bool(data["norm_obs"]):
                return None
            mean, var = np.asarray(data["mean"], dtype=float), np.asarray(data["var"], dtype=float)
            clip, epsilon = float(data["clip_obs"]), float(data["epsilon"])
    except (OSError, KeyError, ValueError, TypeError) as err:
        raise ValueError(f"{path} is not an observation normalisation file ({err})") from err
    if mean.ndim != 1 or mean.shape != var.shape or np.any(var < 0) or clip <= 0 or epsilon < 0:
        raise ValueError(f"{path}: mean and var must be equal 1-D arrays, var >= 0, clip_obs > 0")
    return Normalization(mean, var, clip, epsilon)
