"""Fuzzing the public inputs (hypothesis): every constructor field, ``simulate``'s arguments and the
trajectory loader take anything at all and either work or raise ValueError, never another error."""

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from ballenv.physics import Drum, Ground, Ring, Scene, Trajectory, simulate

SETTINGS = dict(derandomize=True, deadline=None, max_examples=150, suppress_health_check=list(HealthCheck))

ANYTHING = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-(10**30), 10**30),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=5),
    st.tuples(st.floats(allow_nan=True, allow_infinity=True), st.floats(allow_nan=True, allow_infinity=True)),
    st.lists(st.floats(-1e3, 1e3), max_size=3),
    st.just(object()),
)


def fields(cls):
    return [f.name for f in dataclasses.fields(cls)]


@pytest.mark.parametrize("cls", [Ring, Ground, Drum])
@settings(**SETTINGS)
@given(data=st.data())
def test_a_description_takes_any_value_or_names_it(cls, data):
    name = data.draw(st.sampled_from(fields(cls)))
    value = data.draw(ANYTHING)
    try:
        cls(**{name: value})
    except ValueError as err:
        assert name in str(err)


@settings(**SETTINGS)
@given(data=st.data())
def test_a_scene_takes_any_value_or_names_it(data):
    name = data.draw(st.sampled_from([f for f in fields(Scene) if f not in ("rings", "grounds", "drums")]))
    value = data.draw(ANYTHING)
    try:
        Scene(rings=[Ring(n_nodes=8)], **{name: value})
    except ValueError as err:
        assert name in str(err)


SCENE = Scene(rings=[Ring(n_nodes=8, position=(0.0, 0.5))], grounds=[Ground()], dt=5e-3)
STATE = st.one_of(
    ANYTHING,
    st.builds(lambda s: np.full((1, 8, 2), s), st.floats(allow_nan=True, allow_infinity=True)),
    st.builds(lambda n: np.zeros(n), st.integers(0, 20)),
)


@settings(**{**SETTINGS, "max_examples": 60})
@given(
    t_end=st.one_of(ANYTHING, st.floats(1e-4, 5e-3)),
    output_dt=st.one_of(st.none(), ANYTHING),
    x0=st.one_of(st.none(), STATE),
    v0=st.one_of(st.none(), STATE),
)
def test_simulate_takes_any_arguments_or_names_them(t_end, output_dt, x0, v0):
    try:
        traj = simulate(SCENE, t_end, x0=x0, v0=v0, output_dt=output_dt)
    except ValueError as err:
        assert any(name in str(err) for name in ("t_end", "output_dt", "x0", "v0"))
    else:
        assert math.isclose(traj.t[-1], float(t_end)) and np.all(np.isfinite(traj.x))


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    return simulate(SCENE, 0.02).save(tmp_path_factory.mktemp("fuzz") / "run.npz").read_bytes()


@settings(**{**SETTINGS, "max_examples": 200})
@given(data=st.data())
def test_the_loader_takes_any_damage_or_says_so(saved, tmp_path_factory, data):
    raw = bytearray(saved)
    for _ in range(data.draw(st.integers(1, 4))):
        where = data.draw(st.integers(0, len(raw) - 1))
        if data.draw(st.booleans()):
            raw[where] = data.draw(st.integers(0, 255))
        else:
            raw = raw[:where]
        if not raw:
            break
    path = tmp_path_factory.mktemp("damaged") / "run.npz"
    path.write_bytes(bytes(raw))
    try:
        Trajectory.load(path)
    except ValueError as err:
        assert str(path) in str(err)
