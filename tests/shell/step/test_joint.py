"""The joint step's records: a group of one shell with self-contact and a group of two take the
same compiled step (the tuple of shells padded to the same numba type)."""

from numba import typeof

from ballenv.shell import Scene, Shell
from ballenv.shell.simulation import build
from ballenv.shell.step import joint


def test_a_group_of_one_and_a_group_of_two_give_the_compiled_step_the_same_types():
    shells = [Shell(position=(-0.135, 0, 0)), Shell(position=(0.135, 0, 0))]
    _, steps = build(Scene(shells=shells, gravity=0.0, self_contact=True))
    one, two = joint.padded((steps[0],)), joint.padded(tuple(steps))
    assert len(one) == len(two) == joint.SHARED_GROUP
    assert one[0] is steps[0] and two == tuple(steps)
    assert typeof(one) == typeof(two)
    assert typeof((steps[0],)) != typeof(one)  # the unpadded tuple is a type of its own
