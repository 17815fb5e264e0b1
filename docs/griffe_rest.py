"""A Griffe extension (mkdocs.yml: mkdocstrings' ``extensions``) for the API reference: the bits of
reStructuredText some docstrings use, shown as Sphinx would show them instead of as Markdown reads
them. Sphinx roles (``:class:`Scene```, ``:func:`~.simulate.simulate```) become code spans
(``Scene``, ``simulate``); a paragraph ending in ``::`` (a literal block follows) ends in ``:``;
a simple table (rows between ``=====  ====`` borders) becomes a code block, as written.
"""

import re

from griffe import Extension

ROLE = re.compile(r":(?:py:)?(?:class|func|meth|mod|attr|data|obj|exc):`(~?)\.?([^`]+)`")
TABLE_BORDER = re.compile(r"^\s*=+(?: +=+)+\s*$")
LITERAL_MARKER = re.compile(r"(?<=\S)::$", re.MULTILINE)


def plain_roles(text):
    """``text`` with each Sphinx role as a code span of its target (its last part after ``~``)."""

    def code(role):
        short, target = role.groups()
        return f"`{target.split('.')[-1] if short else target}`"

    return ROLE.sub(code, text)


def fenced_tables(text):
    """``text`` with each reST simple table (three border lines: top, under the header, bottom)
    inside a fenced code block."""
    out, borders = [], 0
    for line in text.split("\n"):
        if TABLE_BORDER.match(line):
            borders += 1
            if borders == 1:
                out.append("```text")
            out.append(line)
            if borders == 3:
                out.append("```")
                borders = 0
        else:
            out.append(line)
    return "\n".join(out)


def markdown_of(docstring):
    """A docstring's reST bits (module doc) in Markdown."""
    return LITERAL_MARKER.sub(":", fenced_tables(plain_roles(docstring)))


class RestAsMarkdown(Extension):
    """Rewrites every docstring before mkdocstrings renders it."""

    def on_object(self, *, obj, **kwargs):
        if obj.docstring is not None:
            obj.docstring.value = markdown_of(obj.docstring.value)
