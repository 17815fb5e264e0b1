"""The rules' drop tests of regulation balls, shared by the ring's balls (``ballenv.balls``) and the
3-D ones (``ballenv.shell.balls``): the ball released at rest onto a rigid floor from a stated
height, its rebound measured to a stated point of the ball (SI units)."""

from dataclasses import dataclass


@dataclass(frozen=True)
class DropTest:
    """A rule's drop test: the ball released at rest onto a rigid floor, its rebound measured.

    Attributes:
        drop_height: height (m) of the ball's bottom above the floor at release.
        rebound: the rule's range (m) of the rebound height.
        measured_to: the point of the ball the rebound height is measured to, "bottom" or "top".
        rule: where the test is stated.
    """

    drop_height: float
    rebound: tuple[float, float]
    measured_to: str
    rule: str

    @property
    def target(self) -> float:
        """The middle of the rule's range (m): what a fit of a ball's loss aims at."""
        return 0.5 * (self.rebound[0] + self.rebound[1])


FIBA_DROP = DropTest(1.8, (1.2, 1.4), "top", "FIBA Official Basketball Rules 2020, Basketball Equipment, 2")
ITF_DROP = DropTest(2.54, (1.35, 1.47), "bottom", "ITF Rules of Tennis, Appendix I (onto concrete)")
FIFA_DROP = DropTest(
    2.0, (1.35, 1.55), "bottom", "FIFA Quality Programme for Footballs (onto a steel plate, 20 C)"
)
