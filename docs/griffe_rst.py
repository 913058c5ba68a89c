"""A Griffe extension for the API page: the docstrings' reST roles and maths, rendered.

The toolkit's docstrings are numpydoc, with Sphinx cross-reference roles (``:func:`certify```,
``:mod:`stringstab.derive```) and ``.. math::`` blocks.  mkdocstrings parses the numpydoc
sections but shows roles and directives as they are written.  This extension rewrites each
docstring once the package is loaded:

* a role whose target is an object of the package becomes a cross-reference
  (``<autoref identifier=... optional>``): a link where the object is documented on the site,
  its name in code where it is not (``optional``: no warning, ``mkdocs build --strict`` passes);
  the target is resolved as Sphinx does, from the docstring's own module and class outwards;
  ``~`` shows the last component only; a target outside the package is shown as code;
* ``.. math::`` blocks and ``:math:`` roles are typeset at build time by the report's renderer
  (:func:`stringstab.report.maths.typeset`, matplotlib's mathtext to SVG), embedded as images,
  so the site loads no script and no font for them.

Loaded by ``mkdocs.yml`` (``plugins: mkdocstrings: handlers: python: options: extensions``).
"""

from __future__ import annotations

import html
import re
from typing import Any

import griffe

ROLE = re.compile(r":(?P<role>mod|func|class|data|meth|attr|exc|obj|const):`(?P<body>[^`]+)`")
MATH_ROLE = re.compile(r":math:`(?P<tex>[^`]+)`")
MATH_BLOCK = re.compile(r"^(?P<indent>[ \t]*)\.\. math::[ \t]*(?P<first>.*)\n"
                        r"(?P<body>(?:(?:(?P=indent)[ \t]+.*)?\n)*)", re.MULTILINE)


def _objects(obj: Any) -> Any:
    """Every object under ``obj`` (itself first), aliases left out."""
    yield obj
    for member in list(obj.members.values()):
        if member.is_alias:
            continue
        yield from _objects(member)


def _lookup(pkg: Any, path: str) -> Any:
    """The object at a dotted ``path`` of the package, or None."""
    root, _, rest = path.partition(".")
    if root != pkg.name:
        return None
    try:
        return pkg[rest] if rest else pkg
    except (KeyError, griffe.AliasResolutionError, griffe.CyclicAliasError):
        return None


def _resolve(pkg: Any, obj: Any, target: str) -> str | None:
    """The full path of ``target`` as Sphinx would find it from ``obj``, or None."""
    target = target.lstrip(".")
    scopes = []
    scope = obj
    while scope is not None:
        scopes.append(scope.path)
        scope = scope.parent
    for base in (*scopes, ""):
        path = f"{base}.{target}" if base else target
        if _lookup(pkg, path) is not None:
            return path
    return None


def _role(pkg: Any, obj: Any, m: re.Match[str]) -> str:
    body = m.group("body").strip()
    text, _, explicit = body.partition(" <")
    if explicit:
        target, shown = explicit.rstrip(">"), text
    else:
        target = body.lstrip("~!")
        shown = target.rsplit(".", 1)[-1] if body.startswith("~") else target
    if m.group("role") in ("func", "meth") and not shown.endswith(")"):
        shown += "()"
    target = target.lstrip("~!").removesuffix("()")
    code = f"<code>{html.escape(shown)}</code>"
    path = _resolve(pkg, obj, target)
    if path is None:
        return code
    return f'<autoref identifier="{html.escape(path)}" optional>{code}</autoref>'


def _math_block(m: re.Match[str]) -> str:
    from stringstab.report.maths import typeset

    lines = [m.group("first"), *m.group("body").splitlines()]
    tex = " ".join(line.strip() for line in lines if line.strip())
    return f'{m.group("indent")}<p class="math">{typeset(tex, display=True).img()}</p>\n\n'


def _math_role(m: re.Match[str]) -> str:
    from stringstab.report.maths import typeset

    return typeset(m.group("tex")).img()


def rewrite(text: str, pkg: Any, obj: Any) -> str:
    """The docstring ``text`` of ``obj`` with its roles and maths rendered.

    Parameters
    ----------
    text : str
        The docstring.
    pkg : griffe.Module
        The package (for resolving targets).
    obj : griffe.Object
        The object the docstring belongs to.

    Returns
    -------
    str
        Markdown with inline HTML.
    """
    text = MATH_BLOCK.sub(_math_block, text)
    text = MATH_ROLE.sub(_math_role, text)
    return ROLE.sub(lambda m: _role(pkg, obj, m), text)


class SphinxRoles(griffe.Extension):
    """Rewrite every docstring of the package once it is loaded (see the module docstring)."""

    def on_package(self, *, pkg: Any, **kwargs: Any) -> None:
        """Rewrite the docstrings of ``pkg`` and everything in it.

        Parameters
        ----------
        pkg : griffe.Module
            The loaded package.
        **kwargs
            Griffe's other arguments (unused).
        """
        for obj in _objects(pkg):
            if obj.docstring is not None:
                obj.docstring.value = rewrite(obj.docstring.value, pkg, obj)
