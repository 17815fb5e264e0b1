"""A run folder is code: a model is loaded only if this user's training signed it, or on --trust."""

import os
import pickle
import stat

import gymnasium as gym
import numpy as np
import pytest

import ballenv  # noqa: F401  (registers the env)
from agents.baselines import ModelPolicy, _normalization
from agents.evaluate import main
from agents.normalization import Normalization
from agents.normalization import load as load_normalization
from agents.normalization import save as save_normalization
from agents.signatures import UntrustedFile, key, key_path, sign, signed


@pytest.fixture(autouse=True)
def own_key(tmp_path, monkeypatch):
    monkeypatch.setenv("BALLENV_RUN_KEY", str(tmp_path / "keys" / "run-key"))


class Payload:
    """Unpickling this touches a file: what a crafted pickle in a run folder could do."""

    def __init__(self, marker):
        self.marker = str(marker)

    def __reduce__(self):
        return (os.mknod if hasattr(os, "mknod") else open, (self.marker,))


def crafted_run(tmp_path):
    run = tmp_path / "downloaded_run"
    run.mkdir()
    marker = tmp_path / "the pickle ran"
    (run / "model.zip").write_bytes(pickle.dumps(Payload(marker)))
    (run / "vecnormalize.pkl").write_bytes(pickle.dumps(Payload(marker)))
    return run, marker


def test_a_crafted_run_folder_is_refused_before_anything_is_unpickled(tmp_path, capsys):
    run, marker = crafted_run(tmp_path)
    env = gym.make("InflatedBall-v3")
    with pytest.raises(UntrustedFile, match="not written by this user's ballenv training"):
        ModelPolicy(env, run, algo="ppo")
    with pytest.raises(UntrustedFile, match="pass --trust"):
        _normalization(run / "model.zip", trust=False)
    with pytest.raises(SystemExit):
        main([str(run), "--episodes", "1"])
    assert "--trust" in capsys.readouterr().err
    assert not marker.exists()
    env.close()


def test_signing_is_tied_to_the_bytes_and_to_this_users_key(tmp_path, monkeypatch):
    model = tmp_path / "model.zip"
    model.write_bytes(b"the model")
    assert not signed(model)
    sign([model])
    assert signed(model)
    model.write_bytes(b"the model, changed")
    assert not signed(model)
    sign([model])
    monkeypatch.setenv("BALLENV_RUN_KEY", str(tmp_path / "other user" / "run-key"))
    assert not signed(model)  # a signatures.json made with another key signs nothing here


def test_the_key_is_private_and_refused_when_others_can_read_it(tmp_path):
    first = key()
    assert len(first) == 32 and key() == first
    assert stat.S_IMODE(key_path().stat().st_mode) == 0o600
    key_path().chmod(0o644)
    with pytest.raises(ValueError, match="readable by no other"):
        key()


def test_saved_normalization_is_plain_data_and_applies_as_vecnormalize_does(tmp_path):
    from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize

    venv = VecNormalize(DummyVecEnv([lambda: gym.make("InflatedBall-v3")]), gamma=0.99)
    venv.reset()
    for _ in range(5):
        venv.step(np.array([venv.action_space.sample()]))
    path = save_normalization(venv, tmp_path / "vecnormalize.npz")
    with np.load(path, allow_pickle=False) as data:  # no object arrays: nothing to unpickle
        assert all(data[k].dtype != object for k in data.files)
    frozen = load_normalization(path)
    assert isinstance(frozen, Normalization)
    obs = np.asarray(venv.get_original_obs()[0])
    venv.training = False
    np.testing.assert_array_equal(frozen.apply(obs), venv.normalize_obs(obs).astype(np.float32))
    venv.close()
