"""A griffe extension for the Python API pages (``mkdocs.yml``): the package's docstrings use
Sphinx's roles (``:class:`~astralis_des.kinds.KindDefaults```) and literal blocks (``::``),
which Markdown would show as they are; this turns them into Markdown code."""

from __future__ import annotations

import re
from typing import Any

import griffe

ROLE = re.compile(r":(?:class|func|meth|mod|attr|data|exc|obj):`(~?)([^`]+)`")
LITERAL = re.compile(r"::$", re.MULTILINE)


def markdown(text: str) -> str:
    """``:class:`~a.b.C``` -> ```C```, ``:mod:`a.b``` -> ```a.b```; ``text::`` -> ``text:``."""
    text = ROLE.sub(lambda m: f"`{m[2].rsplit('.', 1)[-1] if m[1] else m[2]}`", text)
    return LITERAL.sub(":", text)


class RstRoles(griffe.Extension):
    def on_instance(self, *, obj: griffe.Object, **_: Any) -> None:
        if obj.docstring is not None:
            obj.docstring.value = markdown(obj.docstring.value)
