"""Every public function documents its parameters and its result (numpydoc).

The API reference (docs/api.md, mkdocstrings) is generated from these docstrings, so a
function that takes arguments needs a ``Parameters`` section naming each of them, and one
that returns something a ``Returns`` (or ``Yields``) section.  Read from the source with
:mod:`ast` (nothing is imported), over every module of the package except the generated one.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

PKG = Path(__file__).resolve().parents[2] / "stringstab"
SECTION = re.compile(r"^(\w[\w ]*)\n-{3,}\s*$", re.M)


def sections(doc: str) -> dict[str, str]:
    """The numpydoc sections of ``doc``: title -> body."""
    heads = list(SECTION.finditer(doc))
    return {h.group(1).strip(): doc[h.end():(heads[i + 1].start() if i + 1 < len(heads) else len(doc))]
            for i, h in enumerate(heads)}


def documented_names(body: str) -> set[str]:
    """The parameter names a Parameters section declares (``a, b : type`` lines, unindented)."""
    names: set[str] = set()
    for line in body.splitlines():
        if not line or line[0].isspace():
            continue
        head = line.split(" : ")[0] if " : " in line else line
        names |= {n.strip().lstrip("*") for n in head.split(",") if n.strip()}
    return names


def public_functions() -> list[tuple[str, ast.FunctionDef]]:
    out = []
    for path in sorted(PKG.rglob("*.py")):
        if path.name == "generated.py" and path.parent.name == "derive":
            continue
        rel = path.relative_to(PKG.parent).as_posix()
        for node in ast.parse(path.read_text(encoding="utf-8")).body:
            if (isinstance(node, ast.FunctionDef) and not node.name.startswith("_")
                    and not any(ast.unparse(d).endswith("overload") for d in node.decorator_list)):
                out.append((f"{rel}:{node.name}", node))  # an @overload stub has no docstring
    return out


def arguments(fn: ast.FunctionDef) -> list[str]:
    a = fn.args
    names = [x.arg for x in [*a.posonlyargs, *a.args, *a.kwonlyargs]]
    names += [v.arg for v in (a.vararg, a.kwarg) if v is not None]
    return [n for n in names if n not in ("self", "cls")]


def returns_something(fn: ast.FunctionDef) -> bool:
    r = fn.returns
    if r is None:
        return any(isinstance(n, ast.Return) and n.value is not None for n in ast.walk(fn))
    return not (isinstance(r, ast.Constant) and r.value is None) and ast.unparse(r) not in (
        "None", "NoReturn", "Never")


FUNCTIONS = public_functions()


def test_the_scan_sees_the_package():
    names = {k for k, _ in FUNCTIONS}
    assert "stringstab/certify/api.py:certify" in names
    assert len(FUNCTIONS) > 300


def test_the_checks_can_fail():
    """A function without the sections is flagged (the checks are not vacuous)."""
    fn = ast.parse('def f(a, b) -> int:\n    """Nothing."""\n    return 1\n').body[0]
    assert isinstance(fn, ast.FunctionDef)
    assert missing(fn) == ["Parameters: a, b", "Returns"]


def missing(fn: ast.FunctionDef) -> list[str]:
    doc = ast.get_docstring(fn) or ""
    sec = sections(doc)
    out = []
    args = arguments(fn)
    if args:
        have = documented_names(sec.get("Parameters", ""))
        lacking = [a for a in args if a not in have]
        if lacking:
            out.append("Parameters: " + ", ".join(lacking))
    if returns_something(fn) and not ({"Returns", "Yields"} & sec.keys()):
        out.append("Returns")
    return out


@pytest.mark.parametrize("where, fn", FUNCTIONS, ids=[k for k, _ in FUNCTIONS])
def test_public_function_has_numpydoc_parameters_and_returns(where, fn):
    assert not missing(fn), f"{where}: missing {missing(fn)}"
