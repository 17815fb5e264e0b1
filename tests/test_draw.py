"""The one drawing path: metres to pixels, and what each primitive puts where, in the style's colours."""

import math

import numpy as np
import pytest

from ballenv.draw import STYLE, Canvas, Style, View

VIEW = View(width=200, height=100, scale=100.0, x0=-1.0, y0=-0.2)  # 2 m x 1 m, floor 20 px up


def colour_count(image, colour, tol=0):
    return int(np.all(np.abs(image.astype(int) - colour) <= tol, axis=-1).sum())


def circle(centre, radius, n=48):
    theta = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    return np.stack([centre[0] + radius * np.cos(theta), centre[1] + radius * np.sin(theta)], axis=1)


def test_view_maps_metres_to_pixels_y_up():
    np.testing.assert_array_equal(
        VIEW.px([[-1.0, -0.2], [1.0, 0.8], [0.0, 0.0]]), [[0, 100], [200, 0], [100, 80]]
    )
    centred = View.centred(200, 100, 100.0, (0.0, 0.3))
    assert (centred.x0, centred.y0) == pytest.approx((-1.0, -0.2))
    np.testing.assert_allclose(centred.centre(), [0.0, 0.3])


def test_style_as_json_gives_css_colours_and_numbers():
    style = STYLE.as_json()
    assert style["rings"][0] == "#c83c28" and style["ground"] == "#969696" and style["force"] == "#1e6ec8"
    assert style["line_width"] == 2 and style["force_scale"] == 0.002 and style["dash"] == [8, 16]
    assert STYLE.ring(5) == STYLE.rings[1]


def test_a_floor_fills_below_its_height_and_nothing_above():
    canvas = Canvas(VIEW)
    canvas.ground(0.0, 0.0)
    image = canvas.array()
    assert image.shape == (100, 200, 3) and image.dtype == np.uint8
    assert np.all(image[81:] == STYLE.ground) and np.all(image[:79] == STYLE.background)


@pytest.mark.parametrize(
    ("angle", "solid", "free"),
    [
        (math.pi / 2, (50, 150), (50, 50)),  # a right wall through x = 0: solid to the right
        (-math.pi / 2, (50, 50), (50, 150)),  # a left wall: solid to the left
        (math.pi, (10, 100), (90, 100)),  # a ceiling at y = 0: solid above
        (0.3, (95, 190), (50, 20)),  # a slope rising to the right
    ],
)
def test_walls_ceilings_and_slopes_fill_their_solid_side(angle, solid, free):
    canvas = Canvas(VIEW)
    canvas.ground(angle, 0.0, 0.0)
    image = canvas.array()
    assert tuple(image[solid]) == STYLE.ground and tuple(image[free]) == STYLE.background


def test_rings_take_their_colours_and_forces_draw_only_where_nonzero():
    canvas = Canvas(VIEW)
    nodes = circle((0.0, 0.3), 0.2)
    canvas.ring(nodes, 0)
    canvas.ring(circle((0.6, 0.3), 0.1), 1)
    forces = np.zeros_like(nodes)
    canvas.forces(nodes, forces)
    assert colour_count(canvas.array(), STYLE.force) == 0
    forces[36] = (0.0, 100.0)  # the lowest node, pushed up: an arrow 0.2 m = 20 px long
    canvas.forces(nodes, forces)
    image = canvas.array()
    assert colour_count(image, STYLE.ring(0)) > 200 and colour_count(image, STYLE.ring(1)) > 100
    arrow = np.argwhere(np.all(image == STYLE.force, axis=-1))
    assert arrow[:, 0].max() - arrow[:, 0].min() == pytest.approx(20, abs=1)
    assert abs(arrow[:, 1].mean() - 100) < 1.5  # under the ring's centre


def test_target_level_is_dashed_across_the_width():
    canvas = Canvas(VIEW)
    canvas.level(0.5)
    row = canvas.array()[30]  # 0.5 m is 70 px up from the foot
    on = np.all(row == STYLE.target, axis=-1)
    dash, period = STYLE.dash
    assert on[:dash].all() and not on[dash + 1 : period].any() and on[period : period + dash].all()
    starts = np.flatnonzero(np.diff(on.astype(int), prepend=0) == 1)
    np.testing.assert_array_equal(starts, np.arange(0, VIEW.width, period))  # one dash per period


def test_paddle_shades_its_reach_over_the_middle_third():
    canvas = Canvas(VIEW)
    canvas.paddle(0.4, 0.1, striking=False)
    image = canvas.array().astype(int)
    alpha = STYLE.reach_alpha / 255
    shade = np.round((1 - alpha) * np.array(STYLE.background) + alpha * np.array(STYLE.paddle))
    np.testing.assert_allclose(image[45, 100], shade, atol=1)  # inside the reach, off the bar
    assert tuple(image[45, 10]) == STYLE.background  # outside the middle third
    assert tuple(image[40, 100]) == STYLE.paddle  # the bar at 0.4 m
    thin = colour_count(image, STYLE.paddle)
    striking = Canvas(VIEW)
    striking.paddle(0.4, 0.1, striking=True)
    assert colour_count(striking.array(), STYLE.paddle) == pytest.approx(2 * thin, rel=0.1)


def test_text_is_drawn_in_the_text_colour_and_a_new_style_recolours_everything():
    canvas = Canvas(VIEW)
    canvas.text(["t = 0.10 s", "p = 30 kPa"], size=12)
    image = canvas.array()
    dark = np.argwhere(np.all(np.abs(image.astype(int) - STYLE.text) < 60, axis=-1))
    assert len(dark) > 30 and dark[:, 0].max() > 20  # two lines
    dark_style = Style(background=(0, 0, 0), ground=(255, 255, 255))
    canvas = Canvas(VIEW, dark_style)
    canvas.ground(0.0, 0.0)
    assert tuple(canvas.array()[10, 10]) == (0, 0, 0) and tuple(canvas.array()[90, 10]) == (255, 255, 255)


def test_array_is_a_new_writable_copy():
    canvas = Canvas(VIEW)
    first = canvas.array()
    first[:] = 0
    assert tuple(canvas.array()[0, 0]) == STYLE.background
