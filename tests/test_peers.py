"""The peer benchmark (benchmarks/peers.py) in reduced form: ballenv's side of the 1-s drop against
the stored reference apex, PyElastica's side when pyelastica is installed (``ballenv[peers]``)."""

import math

import numpy as np
import pytest

from .benchmark_modules import load_benchmark

peers = load_benchmark("peers")


def test_every_named_setting_is_a_valid_scene():
    # the lists the lead edits: every label unique, every setting a Scene ballenv accepts
    settings = [peers.REFERENCE, peers.REFERENCE_CHECK, peers.QUICK_REFERENCE, *peers.BALLENV_SETTINGS]
    labels = [label for label, _ in settings]
    assert len(set(labels)) == len(labels)
    for _, numerics in settings:
        assert peers.drop_scene(**numerics).rings[0].pressure == 1e3
    assert set(peers.QUICK_BALLENV) <= set(labels)
    assert set(peers.QUICK_ELASTICA) <= {label for label, _ in peers.ELASTICA_SETTINGS}


def test_ballenv_first_apex_within_one_percent_of_the_reference():
    result = peers.run_ballenv(
        "GA adaptive dt<=1e-3 tol=1e-4", dict(adaptive=True, dt=1e-3, impulse_tol=1e-4), 1
    )
    assert result.apex == pytest.approx(peers.REFERENCE_APEX, rel=peers.ONE_PERCENT)
    assert result.wall > 0.0 and result.steps > 0


def test_first_apex_from_records_is_the_parabola_top():
    # a centre of mass that falls, bounces at t = 0.4 s (lowest node on the floor) and rises: y + v^2/2g
    t = np.linspace(0.0, 1.0, 1001)
    v = np.where(t < 0.4, -peers.GRAVITY * t, 3.0 - peers.GRAVITY * (t - 0.4))
    y = np.where(
        t < 0.4,
        1.0 - 0.5 * peers.GRAVITY * t**2,
        0.3 + 3.0 * (t - 0.4) - 0.5 * peers.GRAVITY * (t - 0.4) ** 2,
    )
    low = np.where(np.abs(t - 0.4) < 0.02, 0.0, y - 0.1)
    assert peers.first_apex(y, v, low) == pytest.approx(0.3 + 9.0 / (2 * peers.GRAVITY), rel=1e-12)
    assert math.isnan(peers.first_apex(y[:300], v[:300], low[:300]))  # never rises


def test_main_without_pyelastica_says_how_to_install_it(monkeypatch, capsys):
    monkeypatch.setattr(peers, "elastica_available", lambda: False)
    assert peers.main(["--quick"]) == 2
    assert peers.INSTALL_HINT in capsys.readouterr().err


@pytest.mark.slow  # 40 s compiling PyElastica's own kernels; benchmarks/peers.py runs the same
def test_pyelastica_first_apex_matches_ballenv():
    pytest.importorskip("elastica", reason=f"pyelastica is not installed ({peers.INSTALL_HINT})")
    label, setting = peers.ELASTICA_SETTINGS[0]
    result = peers.run_elastica(label, setting, repeats=1)
    # the same physics up to PyElastica's shear (G = E/3): 0.3-0.4 % above ballenv's reference
    assert result.apex == pytest.approx(peers.REFERENCE_APEX, rel=peers.ONE_PERCENT)
    assert result.steps == round(peers.T_END / setting["dt"])


@pytest.mark.slow  # as above: PyElastica's kernels
@pytest.mark.parametrize(("fraction", "holds"), [(0.95, True), (1.02, False)])
def test_pyelastica_stable_step_limit_is_the_estimate(fraction, holds):
    # the estimate is 2.09e-5 s at G = E/3: 5 % below it the ring holds, 2 % above it blows apart
    pytest.importorskip("elastica", reason=f"pyelastica is not installed ({peers.INSTALL_HINT})")
    ring = peers.Ring(**peers.RING)
    limit = peers.stable_step_estimate(ring, shear=1.0)
    assert limit == pytest.approx(2.09e-5, rel=0.01)
    assert peers.stable_step_estimate(ring, shear=10.0) == pytest.approx(limit / math.sqrt(10), rel=0.05)
    assert peers.elastica_drop(ring, fraction * limit, shear=1.0, t_end=0.02)[4] is holds
