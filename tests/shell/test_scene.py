"""Shell: defaults, derived quantities and the ValueErrors of bad fields."""

import math

import pytest

from ballenv.shell import Shell


def test_defaults_and_derived_quantities():
    shell = Shell()
    assert shell.n_vertices == 162
    assert shell.bending_stiffness == pytest.approx(5e6 * 3e-3**3 / (12 * (1 - 0.45**2)))
    assert Shell(subdivisions=3).n_vertices == 642
    assert Shell(position=[1, 2, 3]).position == (1.0, 2.0, 3.0)


@pytest.mark.parametrize(
    "field, value, words",
    [
        ("radius", -0.1, "Shell.radius = -0.1"),
        ("radius", math.nan, "Shell.radius"),
        ("subdivisions", 7, "Shell.subdivisions = 7 is out of range: must be an integer in [0, 6]"),
        ("subdivisions", 1.5, "Shell.subdivisions"),
        ("youngs_modulus", 0.0, "(0, 1e+12] Pa"),
        ("poisson_ratio", 0.6, "Shell.poisson_ratio = 0.6"),
        ("thickness", 0.1, "Shell.thickness = 0.1 is out of range: must be a finite number in (0, 0.06] m"),
        ("density", -1.0, "kg/m^3"),
        ("pressure", math.inf, "Shell.pressure"),
        ("position", (0, 0), "three finite numbers"),
        ("velocity", (0, 0, math.nan), "Shell.velocity"),
        ("angular_velocity", "abc", "Shell.angular_velocity"),
    ],
)
def test_a_bad_field_names_itself_its_value_and_its_range(field, value, words):
    with pytest.raises(ValueError) as error:
        Shell(**{field: value})
    assert words in str(error.value)


def test_a_ground_normalises_its_normal_and_a_scene_its_gravity():
    from ballenv.shell import Ground, Scene

    assert Ground(normal=(0, 3, 4)).normal == pytest.approx((0.0, 0.6, 0.8))
    assert Scene().gravity_vector == (0.0, 0.0, -9.81)
    assert Scene(gravity=(1, 2, -3)).gravity_vector == (1.0, 2.0, -3.0)


def test_a_moving_ground_keeps_its_motion_and_an_oscillation_needs_a_frequency():
    from ballenv.shell import Ground

    belt = Ground(velocity=(1, 0, 0), friction=0.5)
    assert belt.velocity == (1.0, 0.0, 0.0) and belt.moves
    assert Ground(amplitude=1e-3, frequency=20).moves and not Ground(frequency=20).moves
    assert not Ground().moves
    with pytest.raises(ValueError) as error:
        Ground(amplitude=1e-3)
    assert "Ground.frequency = 0.0 is out of range: must be a finite number in (0, 100000] Hz" in str(
        error.value
    )


@pytest.mark.parametrize(
    "owner, field, value, words",
    [
        (
            "Ground",
            "normal",
            (0, 0, 0),
            "Ground.normal = (0, 0, 0) is out of range: must be a non-zero 3-vector",
        ),
        (
            "Ground",
            "friction",
            -0.1,
            "Ground.friction = -0.1 is out of range: must be a finite number in [0, 10]",
        ),
        ("Ground", "height", math.nan, "Ground.height"),
        (
            "Ground",
            "velocity",
            (0.0, 2e3, 0.0),
            "Ground.velocity = (0.0, 2000.0, 0.0) is out of range: must be three finite numbers in "
            "[-1000, 1000] m/s",
        ),
        ("Ground", "velocity", (1.0, 0.0), "Ground.velocity = (1.0, 0.0) is out of range"),
        (
            "Ground",
            "amplitude",
            -0.01,
            "Ground.amplitude = -0.01 is out of range: must be a finite number in [0, 100] m",
        ),
        (
            "Ground",
            "frequency",
            -1.0,
            "Ground.frequency = -1.0 is out of range: must be a finite number in [0,",
        ),
        ("Ground", "frequency", math.inf, "Ground.frequency = inf is out of range"),
        ("Scene", "shells", (), "Scene.shells = () is out of range: must be a non-empty sequence of Shell"),
        (
            "Scene",
            "gravity",
            -1.0,
            "Scene.gravity = -1.0 is out of range: must be a finite number in [0, 1000]",
        ),
        ("Scene", "damping", -1.0, "Scene.damping"),
        ("Scene", "integrator", "rk4", "one of 'generalized_alpha', 'backward_euler'"),
        ("Scene", "dt", 0.0, "Scene.dt = 0.0 is out of range: must be a finite number in (0, 1] s"),
        ("Scene", "dt_min", 1.0, "Scene.dt_min = 1.0 is out of range"),
        ("Scene", "rtol", 0.0, "Scene.rtol"),
        ("Scene", "adaptive", 1, "Scene.adaptive = 1 is out of range: must be True or False"),
        ("Scene", "newton_max_iter", 0, "an integer in [1, 200]"),
        ("Scene", "contact_distance", 0.0, "Scene.contact_distance"),
    ],
)
def test_a_bad_ground_or_scene_field_names_itself_its_value_and_its_range(owner, field, value, words):
    from ballenv.shell import Ground, Scene

    with pytest.raises(ValueError) as error:
        {"Ground": Ground, "Scene": Scene}[owner](**{field: value})
    assert words in str(error.value)


def test_a_drum_normalises_its_axis_and_a_scene_keeps_its_drums():
    from ballenv.shell import Drum, Scene

    drum = Drum(radius=0.5, centre=(0, 0, 1), axis=(0, 3, 4), friction=0.4, angular_velocity=2, spin_up=0.5)
    assert drum.axis == pytest.approx((0.0, 0.6, 0.8)) and drum.inside and drum.moves
    assert not Drum().moves
    assert Scene(drums=drum).drums == (drum,) and Scene().drums == ()


@pytest.mark.parametrize(
    ("field", "value", "words"),
    [
        ("radius", 0.0, "Drum.radius = 0.0 is out of range: must be a finite number in (0, 1e+06] m"),
        ("radius", math.nan, "Drum.radius = nan is out of range"),
        ("centre", (0.0, 1.0), "Drum.centre = (0.0, 1.0) is out of range: must be three finite numbers"),
        ("axis", (0.0, 0.0, 0.0), "Drum.axis = (0.0, 0.0, 0.0) is out of range: must be a non-zero 3-vector"),
        ("inside", 1, "Drum.inside = 1 is out of range: must be True or False"),
        ("friction", -0.1, "Drum.friction = -0.1 is out of range: must be a finite number in [0, 10]"),
        (
            "angular_velocity",
            2e4,
            "Drum.angular_velocity = 20000.0 is out of range: must be a finite number in",
        ),
        ("spin_up", -1.0, "Drum.spin_up = -1.0 is out of range: must be a finite number in [0, 1e+06] s"),
    ],
)
def test_a_bad_drum_field_names_itself_its_value_and_its_range(field, value, words):
    from ballenv.shell import Drum, Scene

    with pytest.raises(ValueError) as error:
        Drum(**{field: value})
    assert words in str(error.value)
    with pytest.raises(ValueError, match="Scene.drums"):
        Scene(drums=[object()])
