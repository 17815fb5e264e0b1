import pytest

TABLE = """Presets:

=========  ======
preset     nodes
=========  ======
fast       32
balanced   64
=========  ======

After."""


@pytest.mark.parametrize(
    ("docstring", "shown"),
    [
        ("the :class:`Scene`.", "the `Scene`."),
        ("a :class:`~.simulation.Simulation` run", "a `Simulation` run"),
        (":func:`ballenv.simulate`, :py:meth:`~Trajectory.save`", "`ballenv.simulate`, `save`"),
        ("``double backticks`` stay", "``double backticks`` stay"),
        ("raises, e.g.::\n\n    ValueError: ...", "raises, e.g.:\n\n    ValueError: ..."),
        ("a :: b", "a :: b"),
    ],
)
def test_rest_inline_markup_reads_as_sphinx_shows_it(griffe_rest, docstring, shown):
    assert griffe_rest.markdown_of(docstring) == shown


def test_a_simple_table_becomes_a_code_block(griffe_rest):
    lines = griffe_rest.markdown_of(TABLE).split("\n")
    assert lines[2] == "```text" and lines[9] == "```"
    assert lines[3:9] == TABLE.split("\n")[2:8]
    assert lines[-1] == "After."
