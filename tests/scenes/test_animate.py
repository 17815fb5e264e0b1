"""The scenes' videos: panels drawn by the one renderer, MP4 and GIF of the same frames, frames and
seconds read back as written."""

import numpy as np
import pytest

from ballenv.draw import STYLE
from ballenv.physics import Ground, Ring, Scene, simulate
from ballenv.scenes.animate import PANEL, Panel, clip_seconds, frame_indices, render_frames, write_videos
from ballenv.video import video_info


@pytest.fixture(scope="module")
def drops():
    """Two short drops: one onto a floor, one against a right wall (ground at pi/2) in no gravity."""
    floor = Scene(
        rings=[Ring(n_nodes=24, pressure=20e3, position=(0.0, 0.2))],
        grounds=[Ground(friction=0.5)],
        adaptive=True,
        dt=1e-2,
    )
    wall = Scene(
        rings=[Ring(n_nodes=24, pressure=20e3, position=(0.0, 0.0), velocity=(2.0, 0.0))],
        grounds=[Ground(angle=np.pi / 2, x=0.2)],
        gravity=0.0,
        adaptive=True,
        dt=1e-2,
    )
    return simulate(floor, 0.3, output_dt=5e-3), simulate(wall, 0.2, output_dt=5e-3)


def test_frame_indices_take_the_last_record_at_or_before_each_time():
    t = np.array([0.0, 0.1, 0.25, 0.3])
    np.testing.assert_array_equal(frame_indices(t, [0.0, 0.05, 0.1, 0.29, 1.0]), [0, 0, 1, 2, 3])


def test_panels_show_grounds_rings_and_labels_in_the_shared_style(drops):
    floor, wall = drops
    frames = render_frames([floor, wall], n_frames=5, labels=["floor", "wall"])
    widths = [Panel(floor).width, Panel(wall).width]
    assert len(frames) == 5 and frames[0].shape == (PANEL, sum(widths) + 4, 3)
    last = frames[-1]
    left, right = last[:, : widths[0]], last[:, widths[0] + 4 :]
    assert np.all(last[:, widths[0] : widths[0] + 4] == 255)  # the gap between the panels
    for panel in (left, right):
        assert np.all(panel == STYLE.ring(0), axis=-1).sum() > 100
        assert np.all(panel == STYLE.ground, axis=-1).sum() > 1000
    assert np.all(left[-5] == STYLE.ground, axis=-1).mean() > 0.9  # the floor along the foot
    solid = np.all(right == STYLE.ground, axis=-1)
    assert solid[:, -5:].all() and not solid[:, : right.shape[1] // 2].any()  # the wall: right side only


def test_gif_and_mp4_of_one_drawing_have_the_frames_and_seconds_asked_for(drops, tmp_path):
    floor, _ = drops
    assert clip_seconds([floor]) == 4.0  # 0.3 s slowed down to the shortest clip
    gif, mp4 = write_videos([floor], [tmp_path / "drop.gif", tmp_path / "drop.mp4"], n_frames=12, seconds=0.6)
    assert video_info(gif) == (12, 0.6)
    n, seconds = video_info(mp4)
    assert n == 12 and seconds == pytest.approx(0.6, abs=0.011)
    n, seconds = video_info(write_videos([floor], [tmp_path / "slow.mp4"], n_frames=30)[0])
    assert n == 30 and seconds == pytest.approx(4.0, abs=0.011)
