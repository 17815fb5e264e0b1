"""Named scenes from the paper and around it, each with its figure and its measured claim.

    python -m ballenv.scenes --list
    python -m ballenv.scenes bounce-vs-pressure --out out/scenes

==================  =========  =================================================================
name                figure     what it shows
==================  =========  =================================================================
bounce-vs-pressure  fig. 6     first-bounce apex against inflation pressure, E = 10 and 25 MPa
bounce-strip        fig. 5     frames of one bounce, 0.015 s apart
deformation         fig. 7     basketball (local flattening) vs tennis ball (global oval)
rolling             fig. 8     unpressurised rings rolling down a slope, E = 2, 4, 6, 8 MPa
variable-inflation  -          gas pumped in at each apex against the same ball left alone
slope-spin          -          a bounce on a slope with back-spin, none and top-spin
two-balls           -          two balls colliding in flight (oblique, no gravity)
vibrating-plate     -          a ball on a vibrating plate: bifurcation diagram against Gamma
rotating-drum       -          a soft ribbon loop rolling in a rotating drum: aspect ratio vs speed
==================  =========  =================================================================

``run(name, fidelity="balanced", reduced=False)`` returns a :class:`SceneResult` (parameters,
measured numbers, trajectories); the parameters of each scene are in its function's docstring in
:mod:`ballenv.scenes.library`.
"""

from dataclasses import dataclass

from . import library
from .library import SceneResult


@dataclass(frozen=True)
class SceneInfo:
    """A registered scene: ``run(fidelity, reduced, progress) -> SceneResult``; with ``grid``, it
    also takes ``cluster`` and runs its parameter grid as tasks of :func:`ballenv.cluster.run_tasks`."""

    name: str
    figure: str
    summary: str
    run: object
    grid: bool = False


SCENES = {
    s.name: s
    for s in (
        SceneInfo("bounce-vs-pressure", "fig. 6", "bounce height vs inflation pressure, E = 10, 25 MPa",
                  library.bounce_vs_pressure),
        SceneInfo("bounce-strip", "fig. 5", "frames of one bounce, 0.015 s apart", library.bounce_strip),
        SceneInfo("deformation", "fig. 7", "basketball (local) vs tennis ball (global) at one impact speed",
                  library.deformation),
        SceneInfo("rolling", "fig. 8", "unpressurised rings rolling down a slope, E = 2, 4, 6, 8 MPa",
                  library.rolling),
        SceneInfo("variable-inflation", "-", "gas pumped in at each apex vs the same ball left alone",
                  library.variable_inflation),
        SceneInfo("slope-spin", "-", "a bounce on a 0.3 rad slope with back-spin, none, top-spin",
                  library.slope_spin),
        SceneInfo("two-balls", "-", "two balls colliding in flight", library.two_balls),
        SceneInfo("vibrating-plate", "-", "a ball on a vibrating plate: apex heights against Gamma",
                  library.vibrating_plate, grid=True),
        SceneInfo("rotating-drum", "-", "a ribbon loop rolling in a rotating drum: aspect ratio vs speed",
                  library.rotating_drum),
    )
}  # fmt: skip


def get(name):
    """The :class:`SceneInfo` called ``name``; an unknown name raises ValueError listing the names."""
    try:
        return SCENES[name]
    except KeyError:
        raise ValueError(f"unknown scene {name!r}: the scenes are {', '.join(SCENES)}") from None


def run(name, fidelity="balanced", reduced=False, progress=False, cluster=None):
    """Run scene ``name`` (see the module table) and return its :class:`SceneResult`; a scene with a
    parameter grid (``SceneInfo.grid``) runs it on ``cluster`` (:func:`ballenv.cluster.run_tasks`:
    None, "local", "auto" or an address), the others here."""
    info = get(name)
    grid = {"cluster": cluster} if info.grid else {}
    return info.run(fidelity=fidelity, reduced=reduced, progress=progress, **grid)


__all__ = ["SCENES", "SceneInfo", "SceneResult", "get", "run"]
