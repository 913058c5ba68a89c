"""The figures of issue 20 ("the house"): how the package is laid out and how it imports.

Prints, for the tree this script sits in:

* the modules at the package root;
* the largest module (lines);
* import circles and upward arrows (the graph of ``tests/test_house.py``, lazy imports included);
* underscored names imported from another module (``from .x import _private``);
* the places that define the verdict vocabulary ("certified"): module- or class-level
  assignments that spell it out — a verdict word (``"certified"``, ``"not_certified"``,
  ``"inconclusive"``) as a string literal, or integer codes given to a verdict-named target
  (``CERTIFIED = 0``, ``_CERT, _NOT, _INC = ...`` of literals).  A heuristic: a column *named*
  "certified" counts too.

Run: ``python analysis/house_figures.py`` (add ``--json`` for a machine-readable line).
"""

from __future__ import annotations

import ast
import json
import re
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(HERE / "tests"))

import test_house as H  # noqa: E402

VERDICT_NAME = re.compile(r"^_?(NOT_)?CERT(IFIED)?(_CODE)?$|^INCONCLUSIVE$|VERDICT")


def _private_imports() -> list[str]:
    out = []
    for mod, path in H.MODULES.items():
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                base = H._resolve(mod, node.level, node.module)
                if not base.startswith(H.ROOT) or base == mod:
                    continue
                for a in node.names:
                    if a.name.startswith("_") and not a.name.startswith("__"):
                        out.append(f"{mod}: from {base} import {a.name}")
    return out


#: The words of the verdict vocabulary.
VERDICT_WORDS = {"certified", "not_certified", "inconclusive"}


def _defines_verdicts(names: list[str], value: ast.AST) -> bool:
    """An assignment that spells the vocabulary out: a verdict word as a string literal, or a
    verdict-named target given integer literals (the codes)."""
    if "__all__" in names:  # lists function names, defines nothing
        return False
    if any(isinstance(n, ast.Constant) and n.value in VERDICT_WORDS for n in ast.walk(value)):
        return True
    ints = [n for n in ast.walk(value) if isinstance(n, ast.Constant) and type(n.value) is int]
    return bool(ints) and any(VERDICT_NAME.search(n) for n in names)


def _verdict_definitions() -> list[str]:
    out = []
    for mod, path in H.MODULES.items():
        tree = ast.parse(path.read_text(encoding="utf-8"))
        bodies = [tree.body] + [c.body for c in tree.body if isinstance(c, ast.ClassDef)]
        for body in bodies:
            for node in body:
                if isinstance(node, (ast.Assign, ast.AnnAssign)) and node.value is not None:
                    targets = node.targets if isinstance(node, ast.Assign) else [node.target]
                    names = [n.id for t in targets for n in ast.walk(t) if isinstance(n, ast.Name)]
                    if _defines_verdicts(names, node.value):
                        out.append(f"{mod}:{node.lineno} {', '.join(names)}")
    return out


def figures() -> dict[str, object]:
    pkg = H.PKG
    root = sorted(p.name for p in pkg.glob("*.py"))
    sizes = {str(p.relative_to(pkg.parent)): len(p.read_text(encoding="utf-8").splitlines())
             for p in pkg.rglob("*.py") if p.name != "generated.py"}
    largest = max(sizes, key=sizes.__getitem__)
    over = sorted((n for n, s in sizes.items() if s > 500), key=lambda n: -sizes[n])
    g = H.import_graph()
    return {
        "root_modules": len(root), "root": root,
        "largest": f"{largest} ({sizes[largest]} lines)",
        "over_500_lines": [f"{n} ({sizes[n]})" for n in over],
        "circles": H.cycles(g), "upward": sorted(map(list, H.upward(g))),
        "private_imports": _private_imports(),
        "verdict_definitions": _verdict_definitions(),
    }


def main() -> None:
    f = figures()
    if "--json" in sys.argv:
        print(json.dumps(f))
        return
    print(f"modules at the root: {f['root_modules']} ({', '.join(f['root'])})")
    print(f"largest module (generated code aside): {f['largest']}")
    print(f"modules over 500 lines: {len(f['over_500_lines'])}: {', '.join(f['over_500_lines'])}")
    print(f"import circles: {len(f['circles'])} {f['circles'] or ''}")
    print(f"upward arrows: {len(f['upward'])} {f['upward'] or ''}")
    print(f"underscored names imported from another module: {len(f['private_imports'])}")
    for line in f["private_imports"]:
        print("   ", line)
    print(f"places defining the verdict vocabulary ('certified'): {len(f['verdict_definitions'])}")
    for line in f["verdict_definitions"]:
        print("   ", line)


if __name__ == "__main__":
    main()
