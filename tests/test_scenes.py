"""Each scene in reduced form (fast preset, fewer cases) asserts the physical claim it illustrates."""

import json

import numpy as np
import pytest

from ballenv import scenes
from ballenv.scenes.__main__ import main
from ballenv.video import video_info

FAST = {"fidelity": "fast", "reduced": True}
GIF_ONLY = ["--video", "gif", "--frames", "6"]


def test_unknown_scene_lists_the_names():
    with pytest.raises(ValueError, match="unknown scene 'nope': the scenes are bounce-vs-pressure, "):
        scenes.get("nope")


def test_apex_rises_with_pressure_more_for_the_softer_wall():
    res = scenes.run("bounce-vs-pressure", **FAST)
    apex = res.metrics["apex_m"]
    for label in ("10 MPa", "25 MPa"):
        assert np.all(np.diff(apex[label]) > 0.0), apex
    rise = res.metrics["apex_rise_m"]
    assert rise["10 MPa"] > rise["25 MPa"] > 0.05


def test_bounce_strip_frames_every_15_ms():
    res = scenes.run("bounce-strip", **FAST)
    m = res.metrics
    times = np.array(m["frame_times_s"])
    assert len(times) >= 6
    np.testing.assert_allclose(np.diff(times), 0.015, atol=6e-4)
    assert times[0] < m["touchdown_s"] < m["liftoff_s"] < times[-1]
    assert 0.005 < m["contact_duration_s"] < 0.05 and m["max_compression"] > 0.05


def test_tennis_ball_deforms_globally_basketball_locally():
    res = scenes.run("deformation", **FAST)
    basket, tennis = res.metrics["basketball"], res.metrics["tennis ball"]
    assert basket["p_R3_over_EI"] > 1000.0 and tennis["p_R3_over_EI"] < 3.0
    # the tennis ball: an oval, flattened top and sharper sides
    assert tennis["aspect_change"] > 0.3
    assert tennis["curvature_top"] < 0.6 and tennis["curvature_side_over_top"] > 2.0
    # the basketball: a flat patch, the free wall still close to a circle, little aspect change
    assert basket["patch_over_width"] > 0.1
    assert basket["aspect_change"] < 0.15 and basket["aspect_change"] < tennis["aspect_change"] / 3
    assert basket["curvature_top"] > 0.8 and basket["curvature_side_over_top"] < 1.4


def test_rolling_height_grows_with_youngs_modulus():
    res = scenes.run("rolling", **FAST)
    heights = res.metrics["height_over_diameter"]
    assert np.all(np.diff(heights) > 0.02), heights
    assert heights[0] < 0.6 and heights[-1] > 0.75
    assert all(s > 0.05 for s in res.metrics["rolling_speed_m_per_s"])  # they roll down


def test_pumped_ball_bounces_higher_above_its_rest():
    res = scenes.run("variable-inflation", **FAST)
    m = res.metrics
    assert len(m["switch_times_s"]) == len(m["schedule_Pa"]) - 1
    pumped, constant = m["pumped_rise_above_rest_m"], m["constant_rise_above_rest_m"]
    assert pumped[0] == pytest.approx(constant[0])  # the same ball until the first pump
    assert all(p > c for p, c in zip(pumped[1:], constant[1:], strict=False)), (pumped, constant)
    # the gas law at impact: converged (balanced and accurate presets) 89.84 kPa = 1.497 x 60 kPa
    assert m["peak_pressure_Pa"] > 1.4 * max(m["schedule_Pa"])


def test_spin_on_a_slope_trades_for_downhill_speed():
    res = scenes.run("slope-spin", **FAST)
    back, top = res.metrics["cases"]
    assert back["spin_in_rad_per_s"] < 0 < top["spin_in_rad_per_s"]
    assert top["downhill_out_m_per_s"] > back["downhill_out_m_per_s"] + 1.0
    for case in (back, top):
        assert abs(case["spin_out_rad_per_s"]) < abs(case["spin_in_rad_per_s"])
        assert case["normal_out_m_per_s"] > 0.5  # it bounced


def test_two_balls_conserve_momentum_and_rebound():
    res = scenes.run("two-balls", **FAST)
    m = res.metrics
    assert m["momentum_change_relative"] < 1e-9
    assert 0.3 < m["restitution"] < 1.0
    (va, vb) = m["velocity_after_m_per_s"]
    assert va[0] < 0.0 < vb[0]
    assert m["closest_centre_distance_m"] > 0.16  # no tunnelling


def test_a_ball_on_a_vibrating_plate_bounces_regularly_then_doubles_its_period():
    """Balanced preset (the fast one's coarse steps blur the bounce heights), started on the point
    particle's period-1 orbit: at Gamma = 1.3 one apex height (within 5 %) and the map's impact
    phase, at 1.5 two alternating heights; the map with the ring's own restitution puts the period
    doubling in between."""
    from ballenv.scenes.library import plate_impact_phase

    res = scenes.run("vibrating-plate", fidelity="balanced", reduced=True)
    m = res.metrics
    assert m["period"] == [1, 2], m["period"]
    assert 0.4 < m["restitution"] < 0.7
    assert 1.3 < m["theory_period_doubling_at"] < 1.5
    one = np.array(m["apex_heights_m"]["1.3"])
    assert len(one) >= 15 and np.ptp(one) < 0.05 * one.mean()
    phase = np.array(m["impact_phases_rad"]["1.3"])
    assert np.abs(phase - plate_impact_phase(1.3, m["restitution"])).max() < 0.1  # rad
    two = np.array(m["apex_heights_m"]["1.5"])
    even, odd = two[::2], two[1::2]
    assert abs(even.mean() - odd.mean()) > 0.1  # m
    assert np.ptp(even) < 0.02 and np.ptp(odd) < 0.02


def test_a_ribbon_loop_in_a_rotating_drum_rolls_and_elongates_with_speed():
    """Balanced preset (the fast one's spin is 20 % below the accurate preset's here: 66 against 85
    rad/s), the drum at rest and at Fr = Omega^2 R_d / g = 3.9: the loop rolls (its spin within 30 %
    of ``Omega R_d / r``, an oval's tank-treading is not a rigid spin), is longer than at rest
    (aspect ratio up by more than 0.1) and climbs the drum's wall in its sense of turning (centre
    angle 0.2 ... 1.2 rad)."""
    from ballenv.scenes.library import DRUM_RADIUS, RIBBON

    rest, fast = scenes.run("rotating-drum", fidelity="balanced", reduced=True).metrics["rows"]
    assert rest["froude"] == 0.0 and fast["froude"] > 3.5
    rolling = fast["drum_spin_rad_per_s"] * DRUM_RADIUS / RIBBON["radius"]
    assert fast["ribbon_spin_rad_per_s"] == pytest.approx(rolling, rel=0.3)
    assert abs(rest["ribbon_spin_rad_per_s"]) < 1e-6 and abs(rest["centre_angle_rad"]) < 1e-6
    assert fast["aspect"] > rest["aspect"] + 0.1
    assert 0.2 < fast["centre_angle_rad"] < 1.2


def test_cli_writes_figure_video_numbers_and_trajectories(tmp_path, capsys):
    assert (
        main(["two-balls", "--out", str(tmp_path), "--fidelity", "fast", "--reduced", "--frames", "12"]) == 0
    )
    for name in (
        "two-balls.png",
        "two-balls.gif",
        "two-balls.mp4",
        "two-balls.json",
        "two-balls-collision.npz",
    ):
        assert (tmp_path / name).stat().st_size > 500, name
    record = json.loads((tmp_path / "two-balls.json").read_text())
    assert record["parameters"]["speed"] == 3.0 and record["metrics"]["restitution"] > 0.3
    from PIL import Image

    with Image.open(tmp_path / "two-balls.gif") as gif:
        assert gif.n_frames == 12
    assert video_info(tmp_path / "two-balls.mp4") == (12, 4.0)  # 0.25 s slowed down to 4 s
    assert (
        main(["two-balls", "--out", str(tmp_path / "gif"), "--fidelity", "fast", "--reduced"] + GIF_ONLY) == 0
    )
    assert sorted(p.suffix for p in (tmp_path / "gif").iterdir()) == [".gif", ".json", ".npz", ".png"]
    assert main(["--list"]) == 0
    assert "rolling" in capsys.readouterr().out
    with pytest.raises(SystemExit):
        main(["nope", "--out", str(tmp_path)])
    assert "the scenes are" in capsys.readouterr().err
