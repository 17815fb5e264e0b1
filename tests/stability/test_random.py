"""Stability suite, property-based (hypothesis): random valid scenes and action sequences run stable, and
random invalid values (NaN, inf, negative, out of range, wrong shapes and types) raise ValueError
naming the field and the valid range. Seeded (``derandomize``): the same examples on every run;
``benchmarks/soak.py`` runs thousands of fresh ones."""

import math
import re
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from ballenv.envs.inflated_ball import InflatedBallEnv
from ballenv.physics import Ground, Ring, Scene, simulate
from ballenv.physics.base.ring import inflated_radius

from .invariants import audit

SETTINGS = dict(derandomize=True, deadline=None, suppress_health_check=[HealthCheck.too_slow])


# ------------------------------------------------------------------------------ valid scenes
def log_uniform(lo, hi):
    return st.floats(math.log(lo), math.log(hi)).map(math.exp)


@st.composite
def valid_scenes(draw, max_nodes=96):
    """A random scene in the hard cases' ranges: one ring (or two) above a floor or a slope of up
    to 75 degrees, E 0.1 MPa-1 GPa, h/R 0.005-0.3, N 8-``max_nodes``, gauge pressure from none to
    40 % of the wall's bound (at most 10 bar), speeds up to 30 m/s, friction 0-2, any integrator,
    contact method and step control. Returns (scene, t_end)."""
    radius = draw(st.floats(0.05, 0.3))
    modulus = draw(log_uniform(1e5, 1e9))
    thickness = radius * draw(log_uniform(0.005, 0.3))
    width = draw(st.floats(0.005, 0.1))
    burst = 0.5 * modulus * thickness / radius
    pressure = draw(st.one_of(st.none(), st.floats(0.0, min(1e6, 0.4 * burst))))
    angle = math.radians(draw(st.floats(-75.0, 75.0)))
    normal = np.array([-math.sin(angle), math.cos(angle)])
    tangent = np.array([normal[1], -normal[0]])
    base = Ring(
        radius=radius, n_nodes=draw(st.integers(8, max_nodes)), youngs_modulus=modulus, thickness=thickness,
        width=width, density=draw(st.floats(100.0, 3000.0)), pressure=pressure,
    )  # fmt: skip
    lift = inflated_radius(base) + draw(st.floats(1e-3, 0.5))
    speed = st.floats(-30.0, 30.0)
    rings = []
    for k in range(draw(st.integers(1, 2))):
        centre = lift * normal + (3.0 * lift * k) * tangent
        rings.append(
            replace(base, position=tuple(centre), velocity=(draw(speed), draw(speed)),
                    angular_velocity=draw(st.floats(-50.0, 50.0)))
        )  # fmt: skip
    adaptive = draw(st.booleans())
    scene = Scene(
        rings=rings,
        grounds=[Ground(angle=angle, friction=draw(st.floats(0.0, 2.0)))],
        contact=draw(st.sampled_from(["mass_modification", "predictor_corrector"])),
        integrator=draw(st.sampled_from(["backward_euler", "generalized_alpha"])),
        rho_infinity=draw(st.floats(0.0, 1.0)),
        gravity=draw(st.floats(0.0, 20.0)),
        damping=draw(st.sampled_from([0.0, 5.0, 50.0])),
        gas_exponent=draw(st.sampled_from([1.0, 1.4])),
        atmospheric_pressure=draw(st.sampled_from([0.0, 101325.0])),
        adaptive=adaptive,
        dt=draw(log_uniform(1e-4, 1e-2)),
    )
    return scene, draw(st.floats(0.02, 0.15))


@settings(max_examples=50, **SETTINGS)
@given(valid_scenes())
def test_random_valid_scenes_run_stable(case):
    """Finite, above ground, rings apart, t_end or a documented error; energy never above its start
    beyond round-off, with either integrator."""
    scene, t_end = case
    result = audit(scene, t_end)
    assert result.problems() == [], (scene, result)


@settings(max_examples=6, **SETTINGS)
@given(
    st.sampled_from(["pressure", "paddle"]),
    st.integers(0, 2**16),
    st.lists(st.floats(-1.5, 1.5), min_size=50, max_size=300),
)
def test_random_action_sequences_stay_finite_and_in_bounds(mode, seed, actions):
    env = InflatedBallEnv(action_mode=mode)
    env.reset(seed=seed)
    for a in actions:
        obs, reward, terminated, truncated, info = env.step(np.array([a], dtype=np.float32))
        assert env.observation_space.contains(obs) and math.isfinite(reward)
        assert not info["sim_failure"], info["sim_failure_reason"]
        assert env._batch.state.x[0, :, 1].min() >= -1e-6
        if terminated:
            env.reset()


# ---------------------------------------------------------------------------- invalid values
NOT_A_NUMBER = st.sampled_from(
    [math.nan, -math.nan, math.inf, -math.inf, "1.0", None, [1.0], (), {}, 1j, b"1", object(), np.nan]
)
NOT_A_BOOL = st.sampled_from([0, 1, 1.0, "True", None, np.float64(1.0), [True]])


def out_of(lo, hi, integer=False):
    """Numbers outside [lo, hi] (and non-numbers; non-integers if ``integer``)."""
    below = st.floats(max_value=lo, exclude_max=True, allow_nan=False, allow_infinity=False)
    above = st.floats(min_value=hi, exclude_min=True, allow_nan=False, allow_infinity=False)
    options = [below, above, NOT_A_NUMBER, st.just(True)]
    if integer:
        options = [st.integers(max_value=lo - 1), st.integers(min_value=hi + 1), NOT_A_NUMBER,
                   st.floats(lo, hi).filter(lambda v: v != int(v))]  # fmt: skip
    return st.one_of(*options)


def open_low(lo, hi):
    return st.one_of(out_of(lo, hi), st.just(lo))


def bad_pair(bound):
    entry = st.one_of(out_of(-bound, bound), st.floats(-bound, bound))
    return st.one_of(
        NOT_A_NUMBER,
        st.floats(-bound, bound),  # a scalar
        st.tuples(entry, out_of(-bound, bound)),
        st.tuples(out_of(-bound, bound), entry),
        st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=5),  # wrong length
        st.just(np.zeros((2, 2))),  # wrong shape
        st.just("ab"),
    )


def bad_choice(choices):
    return st.one_of(
        st.text(max_size=12).filter(lambda s: s not in choices),
        NOT_A_NUMBER,
        st.just(np.array(list(choices))),
        st.just(list(choices)),
    )


RING_FIELDS = {
    "radius": open_low(0.0, 100.0),
    "n_nodes": out_of(3, 4096, integer=True),
    "youngs_modulus": open_low(0.0, 1e12),
    "thickness": st.one_of(open_low(0.0, 0.1), st.floats(0.1, 1e3)),  # must stay below radius 0.1
    "width": open_low(0.0, 100.0),
    "density": open_low(0.0, 1e5),
    "pressure": st.one_of(
        st.floats(max_value=-2.01e5),  # below -E h / (R cos(pi/N)): the wall compressed by 50 %
        st.floats(1e5 + 1.0, 1e30),
        NOT_A_NUMBER.filter(lambda v: v is not None),
    ),  # fmt: skip
    "position": bad_pair(1e6),
    "velocity": bad_pair(1e3),
    "angular_velocity": out_of(-1e5, 1e5),
}
GROUND_FIELDS = {
    "angle": out_of(-math.pi, math.pi),
    "height": out_of(-1e6, 1e6),
    "friction": out_of(0.0, 10.0),
    "x": out_of(-1e6, 1e6),
}
SCENE_FIELDS = {
    "rings": st.one_of(
        st.just([]),
        st.just([1.0]),
        st.just("ring"),
        st.just(None),
        st.just([Ground()]),
        st.just([Ring(n_nodes=8), Ring(n_nodes=16)]),
    ),  # fmt: skip
    "grounds": st.one_of(st.just([1.0]), st.just(3), st.just([Ring()])),
    "contact": bad_choice(("mass_modification", "predictor_corrector")),
    "impulse_tol": open_low(0.0, 10.0).filter(lambda v: v is not None),  # None: the default, valid
    "friction_regularization": open_low(0.0, 1.0),
    "gravity": st.one_of(
        out_of(0.0, 1000.0).filter(lambda v: not isinstance(v, (list, tuple))),
        bad_pair(1000.0).filter(lambda v: not isinstance(v, float)),
    ),  # fmt: skip
    "damping": out_of(0.0, 1e6),
    "damping_mode": bad_choice(("rigid", "centre_of_mass")),
    "integrator": bad_choice(("backward_euler", "generalized_alpha")),
    "rho_infinity": out_of(0.0, 1.0),
    "dt": open_low(0.0, 1.0),
    "adaptive": NOT_A_BOOL,
    "dt_min": st.one_of(open_low(0.0, 1e-2), st.floats(1e-2, 1.0, exclude_min=True)),  # dt = 1e-2
    "newton_tol": out_of(1e-14, 1e-2),
    "newton_max_iter": out_of(1, 200, integer=True),
    "newton_rescue_max_iter": out_of(0, 200, integer=True),
    "atmospheric_pressure": out_of(0.0, 1e7),
    "gas_exponent": out_of(0.0, 3.0),
    "ring_collision": NOT_A_BOOL,
    "self_intersection": bad_choice(("barrier", "reject", "ignore")),
}
ENV_FIELDS = {
    "action_mode": bad_choice(("pressure", "paddle")),
    "fidelity": bad_choice(("fast", "balanced", "accurate")),
    "control_frequency": out_of(1.0, 1e4),
    "pressure_rate": out_of(0.0, 1e12),
    "paddle_max_impulse": out_of(0.0, 10.0),
    "damping": out_of(0.0, 1e4),
    "friction": out_of(0.0, 10.0),
    "youngs_modulus": open_low(0.0, 1e12),
    "target_height_range": st.one_of(bad_pair(1e3), st.just((1.0, 0.5)), st.just((0.5, 1e9))),
    "pressure_range": st.one_of(bad_pair(1e8), st.just((5e4, 1e4)), st.just((-1.0, 1e4))),
}


def _assert_names_field(err, owner, field):
    message = str(err.value)
    assert re.search(rf"{owner}\.{field}\b", message), message  # owner: a regular expression
    assert "must" in message, message  # ... followed by the valid range or choices


@pytest.mark.parametrize(
    ("cls", "field"),
    [(Ring, f) for f in RING_FIELDS]
    + [(Ground, f) for f in GROUND_FIELDS]
    + [(Scene, f) for f in SCENE_FIELDS],
    ids=lambda v: v.__name__ if isinstance(v, type) else v,
)
def test_invalid_ring_ground_and_scene_values_raise_naming_field_and_range(cls, field):
    fields = {Ring: RING_FIELDS, Ground: GROUND_FIELDS, Scene: SCENE_FIELDS}[cls]

    @settings(max_examples=25, **SETTINGS)
    @given(fields[field])
    def run(value):
        with pytest.raises(ValueError) as err:
            cls(**{field: value})
        _assert_names_field(err, cls.__name__, field)

    run()


@pytest.mark.parametrize("field", list(ENV_FIELDS))
def test_invalid_env_arguments_raise_naming_field_and_range(field):
    @settings(max_examples=10, **SETTINGS)
    @given(ENV_FIELDS[field])
    def run(value):
        with pytest.raises(ValueError) as err:
            InflatedBallEnv(**{field: value})
        _assert_names_field(err, "(InflatedBall-v3|Ring)", field)  # material: checked by Ring

    run()


SMALL = Scene(rings=[Ring(n_nodes=8, position=(0.0, 0.0))], gravity=0.0)


@settings(max_examples=40, **SETTINGS)
@given(out_of(0.0, 1e6).filter(lambda v: not (isinstance(v, float) and v == 0.0)) | st.just(0.0))
def test_invalid_t_end_raises(t_end):
    with pytest.raises(ValueError) as err:
        simulate(SMALL, t_end)
    _assert_names_field(err, "simulate", "t_end")


@settings(max_examples=40, **SETTINGS)
@given(
    st.sampled_from(["x0", "v0"]),
    st.one_of(
        NOT_A_NUMBER,
        st.integers(0, 12).flatmap(lambda n: st.just(np.zeros((n, 2)))).filter(lambda a: a.shape[0] != 8),
        st.just(np.zeros((8, 3))),
        st.just(np.zeros((2, 8, 2))),
        st.integers(0, 15).map(lambda k: np.where(np.arange(16).reshape(8, 2) == k, np.nan, 0.0)),
        st.integers(0, 15).map(lambda k: np.where(np.arange(16).reshape(8, 2) == k, -np.inf, 0.0)),
        st.just(np.full((8, 2), "a")),
        st.just(np.zeros((8, 2), dtype=complex)),
        st.just([[0.0, 0.0]] * 7 + [[0.0]]),  # ragged
    ),
)
def test_invalid_start_states_raise(name, value):
    with pytest.raises(ValueError) as err:
        simulate(SMALL, 1e-3, **{name: value})
    assert f"simulate.{name}" in str(err.value) and "must be" in str(err.value)


@settings(max_examples=40, **SETTINGS)
@given(
    st.one_of(
        NOT_A_NUMBER.filter(lambda v: not isinstance(v, list)),  # [1.0] is a valid action
        st.just(np.zeros(2, dtype=np.float32)),
        st.just(np.zeros((1, 2))),
        st.just(np.array([True])),
        st.just(np.array(["1"])),
        st.just(np.array([1j])),
    )
)
def test_invalid_actions_raise_naming_the_action(action):
    env = InflatedBallEnv()
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"action.*must be"):
        env.step(action)
