"""The 3-D renderer: a resting ball drawn where the camera's projection puts it, lit, shadowed and
hidden in the right places, the same every time; its inputs checked; clips paced in real time."""

import math
from types import SimpleNamespace

import numpy as np
import pytest

from ballenv.draw3d import (
    STYLE3D,
    Camera,
    Paddle,
    Spot,
    Style3D,
    clip_frames,
    colormap,
    draw,
    frame_times,
    resample,
    write_clip,
)
from ballenv.shell.skin.mesh import icosphere

MESH = icosphere(2)
TRIANGLES = MESH.triangles
RADIUS = 0.1  # m
CENTRE = np.array([0.0, 0.0, 0.1])  # m: resting on the ground z = 0
FLOOR = [((0.0, 0.0, 1.0), 0.0)]
CAMERA = Camera(target=tuple(CENTRE), distance=1.0, elevation=0.3)
UNIFORM = Style3D(floor=((200, 200, 200), (200, 200, 200)), light=(-1.0, 0.0, 1.0), fog=1e6)


def ball(centre=CENTRE, radius=RADIUS):
    return (MESH.vertices * radius + centre)[None]


def pixel(camera, point):
    """(row, column) of the pixel whose centre is nearest the projection of ``point``."""
    xy, _ = camera.project(point)
    return int(xy[1]), int(xy[0])


def is_ball(rgb):
    """Whether a pixel has the first ball's (red) colour."""
    r, g, b = (int(c) for c in rgb)
    return r > 1.5 * g and r > 1.5 * b


@pytest.fixture(scope="module")
def resting():
    return draw(CAMERA, ball(), TRIANGLES, FLOOR)


def test_an_image_is_height_by_width_rgb_bytes(resting):
    assert resting.shape == (360, 480, 3) and resting.dtype == np.uint8
    small = draw(Camera(width=64, height=48), ball(), TRIANGLES, FLOOR)
    assert small.shape == (48, 64, 3) and small.dtype == np.uint8


def test_the_target_projects_to_the_image_centre():
    xy, depth = CAMERA.project(CENTRE)
    np.testing.assert_allclose(xy, (240.0, 180.0))
    np.testing.assert_allclose(depth, 1.0)


def test_the_ball_is_where_the_projection_puts_it(resting):
    assert is_ball(resting[pixel(CAMERA, CENTRE)])
    for side in (-1.0, 1.0):
        assert is_ball(resting[pixel(CAMERA, CENTRE + (side * 0.08, 0.0, 0.0))])
        assert not is_ball(resting[pixel(CAMERA, CENTRE + (side * 0.13, 0.0, 0.0))])


def test_far_from_the_ball_the_sky_is_above_and_the_floor_below(resting):
    r, g, b = (int(c) for c in resting[2, 2])
    assert b > r + 20  # sky: blue
    r, g, b = (int(c) for c in resting[-3, 2])
    assert max(r, g, b) - min(r, g, b) < 20  # floor: grey


def test_the_side_facing_the_light_is_brighter():
    image = draw(CAMERA, ball(), TRIANGLES, FLOOR, style=UNIFORM)  # light from -x and above
    lit = image[pixel(CAMERA, CENTRE + 0.09 * np.array([-0.8, -0.5, 0.3]))].astype(int).sum()
    unlit = image[pixel(CAMERA, CENTRE + 0.09 * np.array([0.8, -0.5, -0.3]))].astype(int).sum()
    assert lit > unlit + 60


def test_the_shadow_is_darker_than_the_floor_beside_it():
    image = draw(CAMERA, ball(), TRIANGLES, FLOOR, style=UNIFORM)  # shadow about x = 0.1, |y| < 0.1
    shadow = image[pixel(CAMERA, np.array([0.2, 0.0, 0.0]))].astype(int)
    beside = image[pixel(CAMERA, np.array([0.2, -0.15, 0.0]))].astype(int)
    assert np.all(shadow < 0.7 * beside)
    unshadowed = draw(CAMERA, ball(), TRIANGLES, FLOOR, style=Style3D(light=(-1.0, 0.0, 1.0), shadow=1.0))
    shaded = draw(CAMERA, ball(), TRIANGLES, FLOOR, style=Style3D(light=(-1.0, 0.0, 1.0)))
    at = pixel(CAMERA, np.array([0.2, 0.0, 0.0]))
    assert shaded[at].astype(int).sum() < unshadowed[at].astype(int).sum()


def test_the_same_input_draws_the_same_image(resting):
    np.testing.assert_array_equal(draw(CAMERA, ball(), TRIANGLES, FLOOR), resting)
    kwargs = dict(values=[30e3], value_range=(0.0, 60e3), spots=[Spot((0.3, 0.0, 0.0))], smooth=False)
    np.testing.assert_array_equal(
        draw(CAMERA, ball(), TRIANGLES, FLOOR, **kwargs), draw(CAMERA, ball(), TRIANGLES, FLOOR, **kwargs)
    )


def test_the_nearer_ball_hides_the_farther_whatever_their_order():
    near, far = ball(CENTRE + (0.0, -0.3, 0.0))[0], ball(CENTRE + (0.0, 0.3, 0.0))[0]
    at = pixel(CAMERA, CENTRE + (0.0, -0.3, 0.0))
    for pair, nearer in (((near, far), 0), ((far, near), 1)):
        image = draw(CAMERA, np.stack(pair), TRIANGLES, FLOOR, values=[0.0, 1.0], value_range=(0.0, 1.0))
        r, _, b = (int(c) for c in image[at])
        assert (b > r) if nearer == 0 else (r > b)  # value 0 is blue, 1 is red


def test_a_ball_under_the_floor_is_hidden():
    image = draw(CAMERA, ball(CENTRE - (0.0, 0.0, 0.5)), TRIANGLES, FLOOR)
    assert not any(is_ball(p) for p in image.reshape(-1, 3)[::7])


def test_flat_and_smooth_shading_differ_only_on_the_ball(resting):
    flat = draw(CAMERA, ball(), TRIANGLES, FLOOR, smooth=False)
    changed = np.any(flat != resting, axis=2)
    assert changed.any()
    assert all(
        is_ball(resting[r, c]) or is_ball(flat[r, c]) for r, c in zip(*np.nonzero(changed), strict=True)
    )


def test_a_spot_and_a_paddle_are_drawn_in_their_colours():
    spot, paddle = Spot((0.3, -0.2, 0.0), radius=0.08, width=0.08), Paddle((-0.3, 0.0, 0.3), (0.3, -1.0, 0.2))
    image = draw(CAMERA, ball(), TRIANGLES, FLOOR, spots=[spot], paddles=[paddle])
    assert image[pixel(CAMERA, np.array(spot.centre))][1] > 100  # green
    r, g, b = (int(c) for c in image[pixel(CAMERA, np.array(paddle.centre))])
    assert b > r + 30 and b > g + 30  # the paddle's dark blue


def test_colormap_maps_the_range_ends_to_blue_and_red():
    low, mid, high = colormap([-5.0, 0.5, 9.0], (0.0, 1.0))
    assert low[2] > low[0] and high[0] > high[2]
    np.testing.assert_allclose(mid, (221 / 255,) * 3)


def test_a_following_camera_closes_the_gap_by_one_minus_exp_of_time_over_lag():
    camera = Camera(target=(0.0, 0.0, 0.0))
    np.testing.assert_allclose(camera.following((1.0, 0.0, 0.0), 0.1, 0.0).target, (1.0, 0.0, 0.0))
    moved = camera.following((1.0, 0.0, 0.0), 0.2, 0.2).target
    np.testing.assert_allclose(moved, (1.0 - math.exp(-1.0), 0.0, 0.0))
    np.testing.assert_allclose(camera.aimed_at((0.0, 2.0, 0.0)).target, (0.0, 2.0, 0.0))


def test_frame_times_step_by_one_over_fps_and_samples_are_interpolated():
    np.testing.assert_allclose(frame_times([0.0, 0.5, 1.0], 10.0), np.arange(11) / 10.0)
    y = np.array([[0.0, 0.0], [2.0, 4.0]])
    np.testing.assert_allclose(resample([0.0, 1.0], y, [0.25, 2.0]), [[0.5, 1.0], [2.0, 4.0]])


def trajectory(n=11, duration=0.5):
    t = np.linspace(0.0, duration, n)
    x = np.stack([ball(CENTRE + (0.5 * s, 0.0, 0.0)) for s in t])
    grounds = [SimpleNamespace(normal=(0.0, 0.0, 1.0), height=0.0)]
    return SimpleNamespace(
        t=t, x=x, pressure=np.linspace(20e3, 30e3, n)[:, None], scene=SimpleNamespace(grounds=grounds)
    )


def test_a_clip_has_one_frame_per_one_over_fps_and_follows_the_ball():
    camera = Camera(target=(0.0, 0.0, 0.1), width=96, height=72)
    frames = list(clip_frames(trajectory(), TRIANGLES, fps=20.0, camera=camera, follow=0.0))
    assert len(frames) == 11 and frames[0].shape == (72, 96, 3)
    first, last = frames[0][36, 48].astype(int), frames[-1][36, 48].astype(int)
    assert first[2] > first[0]  # the ball at the centre, blue at the lowest pressure
    assert last[0] > last[2]  # followed to the centre 0.25 m on, red at the highest pressure


def test_write_clip_writes_a_real_time_video(tmp_path):
    pytest.importorskip("imageio_ffmpeg")
    from ballenv.video import video_info

    path = write_clip(
        trajectory(), TRIANGLES, tmp_path / "clip.mp4", fps=20.0, camera=Camera(width=64, height=48)
    )
    frames, seconds = video_info(path)
    assert frames == 11 and seconds == pytest.approx(11 / 20.0, abs=0.06)


BAD_DRAWS = [
    (dict(positions=np.zeros((162, 3))), "positions shape"),
    (dict(positions=np.full((1, 162, 3), np.nan)), "positions"),
    (dict(triangles=TRIANGLES + 200), r"vertex indices in \[0, 161\]"),
    (dict(triangles=np.zeros((4, 2), dtype=int)), "triangles shape"),
    (dict(values=np.zeros(3), value_range=(0.0, 1.0)), "values shape"),
    (dict(values=[1.0]), "value_range"),
    (dict(values=[1.0], value_range=(1.0, 0.0)), "low < high"),
    (dict(grounds=[((0.0, 0.0, 0.0), 0.0)]), r"grounds\[0\] normal"),
    (dict(spots=[Spot((0.0, 0.0, 0.0), radius=-1.0)]), r"spots\[0\] radius"),
    (dict(paddles=[Paddle((np.inf, 0.0, 0.0))]), r"paddles\[0\] centre"),
]


@pytest.mark.parametrize(("change", "message"), BAD_DRAWS)
def test_bad_input_raises_a_value_error_naming_it_and_its_range(change, message):
    kwargs = dict(positions=ball(), triangles=TRIANGLES, grounds=FLOOR) | change
    with pytest.raises(ValueError, match=message):
        draw(CAMERA, **kwargs)


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("width", 0),
        ("height", 10_000),
        ("elevation", 1.6),
        ("distance", 0.0),
        ("fov", math.nan),
        ("target", (0, 0)),
    ],
)
def test_a_bad_camera_raises_a_value_error_naming_the_field(field, value):
    with pytest.raises(ValueError, match=f"Camera {field}.*must be"):
        Camera(**{field: value})


def test_the_default_style_lights_from_above():
    assert STYLE3D.light_direction()[2] > 0.5


@pytest.mark.parametrize(
    ("field", "value"), [("light", (0, 0, 0)), ("ambient", 1.5), ("tile", 0.0), ("segments", 2)]
)
def test_a_bad_style_raises_a_value_error_naming_the_field(field, value):
    with pytest.raises(ValueError, match=f"Style3D {field}.*must be"):
        Style3D(**{field: value})


def test_a_camera_sliding_along_the_floor_sees_the_floor_pattern_move_with_it():
    moved = Camera(target=(STYLE3D.tile, 0.0, 0.1), distance=1.0, elevation=0.3)  # one tile over
    shifted = draw(moved, ball(CENTRE + (STYLE3D.tile, 0.0, 0.0)), TRIANGLES, FLOOR)
    here = draw(CAMERA, ball(), TRIANGLES, FLOOR)
    assert np.mean(np.any(shifted != here, axis=2)) > 0.3  # the checkerboard's parity flipped
    twice = Camera(target=(2 * STYLE3D.tile, 0.0, 0.1), distance=1.0, elevation=0.3)
    again = draw(twice, ball(CENTRE + (2 * STYLE3D.tile, 0.0, 0.0)), TRIANGLES, FLOOR)
    assert np.mean(np.any(np.abs(again.astype(int) - here) > 2, axis=2)) < 0.01  # two tiles: the same


def test_per_vertex_values_colour_each_part_of_the_ball():
    x = ball()
    height = x[..., 2] - CENTRE[2]  # (1, V): per vertex, -0.1 to 0.1 m
    image = draw(CAMERA, x, TRIANGLES, FLOOR, values=height, value_range=(-0.1, 0.1))
    top = image[pixel(CAMERA, CENTRE + (0.0, -0.05, 0.07))].astype(int)
    bottom = image[pixel(CAMERA, CENTRE + (0.0, -0.05, -0.07))].astype(int)
    assert top[0] > top[2] and bottom[2] > bottom[0]


def test_a_cached_view_draws_the_same_image_as_a_fresh_one():
    from ballenv.draw3d import _view

    _view.cache_clear()
    fresh = draw(CAMERA, ball(), TRIANGLES, FLOOR, spots=[Spot((0.3, 0.0, 0.0))])
    cached = draw(CAMERA, ball(), TRIANGLES, FLOOR, spots=[Spot((0.3, 0.0, 0.0))])
    np.testing.assert_array_equal(fresh, cached)
