"""The figures of issues 20 and 32 ("the house"): how the package is laid out and how it imports.

Prints, for the tree this script sits in (or the checkout given with ``--tree PATH``, e.g. the
main branch before a change; the layer table is always this tree's ``docs/architecture.md``):

* the modules at the package root;
* the largest module (lines);
* import circles and upward arrows (the graph of ``tests/house/test_house.py``, lazy imports included):
  a module importing a package that contains it;
* **arrows that run back up**: every import of a module in a higher layer of the layer table
  of ``docs/architecture.md`` (``tests/test_house.layer_violations``: file, line, both layers);
* underscored names imported from another module (``from .x import _private``);
* the places that define the verdict vocabulary ("certified"): module- or class-level
  assignments that spell it out — a verdict word (``"certified"``, ``"not_certified"``,
  ``"inconclusive"``) as a string literal, or integer codes given to a verdict-named target
  (``CERTIFIED = 0``, ``_CERT, _NOT, _INC = ...`` of literals).  A heuristic: a column *named*
  "certified" counts too;
* **side-door functions**: public certificate entries of ``stringstab.certify`` outside its one
  way in (``certify.api``): a public function of a ``stringstab.certify`` module other than
  ``api``, named ``certify*`` or ``check*``, that takes unchecked gains (a parameter ``k_x``;
  the kernels behind the way in take checked arrays ``kx``) and returns a certificate or a check
  (its return annotation names a ``...Certificate``, ``...CertificateBatch`` or ``...Check``),
  with the modules outside ``stringstab.certify`` that call it;
* **literal verdict comparisons** in the package (read with :mod:`ast`, not grep): a comparison
  (``==``, ``!=``, ``in``, ``not in``, ``is``, ``is not``) with a verdict word as a string
  literal on either side or inside a literal tuple, list or set; a ``case "certified":``; a call
  of ``equal``, ``not_equal`` or ``isin`` with such a literal argument;
* the modules over 500 lines, each with its job where ``tests/house/test_house.py`` lists one;
* the test files: flat (``tests/test_*.py``) and in folders (``tests/**/test_*.py``).

Run: ``python analysis/house_figures.py [--tree PATH] [--json]`` (``--json``: one
machine-readable line).
"""

from __future__ import annotations

import ast
import json
import re
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(HERE / "tests" / "house"))

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


#: Issue 32: the side doors around ``certify.api`` named in the issue (the rule below finds them).
ISSUE_SIDE_DOORS = ("check_sampled", "certify_sampled_batch", "certify_sampled",
                    "certify_robust_batch", "certify_robust", "check_robust")
RESULT = re.compile(r"(Certificate|CertificateBatch|Check)\b")
COMPARE_OPS = (ast.Eq, ast.NotEq, ast.In, ast.NotIn, ast.Is, ast.IsNot)


def _side_doors() -> list[str]:
    """``module.function (callers outside certify)`` for each side-door function (module docstring)."""
    doors: dict[tuple[str, str], list[str]] = {}
    for mod, path in H.MODULES.items():
        if not mod.startswith("stringstab.certify.") or mod == "stringstab.certify.api":
            continue
        for node in ast.parse(path.read_text(encoding="utf-8")).body:
            if (isinstance(node, ast.FunctionDef) and not node.name.startswith("_")
                    and node.name.startswith(("certify", "check"))
                    and "k_x" in [a.arg for a in (*node.args.args, *node.args.kwonlyargs)]
                    and node.returns is not None and RESULT.search(ast.unparse(node.returns))):
                doors[(mod, node.name)] = []
    for mod, path in H.MODULES.items():
        if mod == "stringstab.certify" or mod.startswith("stringstab.certify."):
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"))
        alias: dict[str, str] = {}  # a name bound to a certify module ("from ..certify import sampled")
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                base = H._resolve(mod, node.level, node.module)
                for a in node.names:
                    if (base, a.name) in doors:
                        doors[(base, a.name)].append(f"{mod}:{node.lineno}")
                    if f"{base}.{a.name}" in H.MODULES:
                        alias[a.asname or a.name] = f"{base}.{a.name}"
            elif isinstance(node, ast.Import):
                alias.update({a.asname: a.name for a in node.names if a.asname and a.name in H.MODULES})
        for node in ast.walk(tree):
            if (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name)
                    and (alias.get(node.value.id), node.attr) in doors):
                doors[(alias[node.value.id], node.attr)].append(f"{mod}:{node.lineno}")
    return [f"{m}.{f}" + (f" (called from {', '.join(c)})" if c else "") for (m, f), c in doors.items()]


def _is_verdict_literal(node: ast.AST) -> bool:
    if isinstance(node, ast.Constant):
        return node.value in VERDICT_WORDS
    if isinstance(node, (ast.Tuple, ast.List, ast.Set)):
        return any(isinstance(e, ast.Constant) and e.value in VERDICT_WORDS for e in node.elts)
    return False


def _literal_verdict_comparisons() -> list[str]:
    """``module:line`` of every literal verdict comparison in the package (module docstring)."""
    out: list[tuple[str, int]] = []
    for mod, path in H.MODULES.items():
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Compare):
                hit = (any(isinstance(o, COMPARE_OPS) for o in node.ops)
                       and any(map(_is_verdict_literal, (node.left, *node.comparators))))
            elif isinstance(node, ast.MatchValue):
                hit = _is_verdict_literal(node.value)
            elif isinstance(node, ast.Call):
                name = node.func.attr if isinstance(node.func, ast.Attribute) else getattr(node.func, "id", "")
                hit = name in ("equal", "not_equal", "isin") and any(map(_is_verdict_literal, node.args))
            else:
                continue
            if hit:
                out.append((mod, node.lineno))
    return [f"{m}:{line}" for m, line in sorted(out)]


def _test_files(tests: Path) -> tuple[int, int]:
    """(flat, in folders): the test files directly in ``tests/`` and in its subfolders."""
    flat = len(list(tests.glob("test_*.py")))
    return flat, len(list(tests.rglob("test_*.py"))) - flat


def figures() -> dict[str, object]:
    pkg = H.PKG
    root = sorted(p.name for p in pkg.glob("*.py"))
    sizes = {str(p.relative_to(pkg.parent)): len(p.read_text(encoding="utf-8").splitlines())
             for p in pkg.rglob("*.py") if p.name != "generated.py"}
    largest = max(sizes, key=sizes.__getitem__)
    over = sorted((n for n, s in sizes.items() if s > 500), key=lambda n: -sizes[n])
    g = H.import_graph()
    table = H.layer_table((HERE / "docs" / "architecture.md").read_text(encoding="utf-8"))
    sources = {m: (str(p.relative_to(pkg.parent)), p.read_text(encoding="utf-8"))
               for m, p in H.MODULES.items()}
    flat, folders = _test_files(pkg.parent / "tests")
    return {
        "root_modules": len(root), "root": root,
        "largest": f"{largest} ({sizes[largest]} lines)",
        "over_500_lines": [f"{n} ({sizes[n]})" + (f": {H.LONG_MODULES[n]}" if n in H.LONG_MODULES else "")
                           for n in over],
        "circles": H.cycles(g), "upward": sorted(map(list, H.upward(g))),
        "private_imports": _private_imports(),
        "verdict_definitions": _verdict_definitions(),
        "arrows_back_up": H.layer_violations(sources, table),
        "side_doors": _side_doors(),
        "literal_verdict_comparisons": _literal_verdict_comparisons(),
        "test_files_flat": flat, "test_files_in_folders": folders,
    }


def main() -> None:
    if "--tree" in sys.argv:  # measure another checkout against this tree's layer table
        H.PKG = Path(sys.argv[sys.argv.index("--tree") + 1]).resolve() / "stringstab"
        H.MODULES = H._modules()
    f = figures()
    if "--json" in sys.argv:
        print(json.dumps(f))
        return
    print(f"modules at the root: {f['root_modules']} ({', '.join(f['root'])})")
    print(f"largest module (generated code aside): {f['largest']}")
    print(f"package: {H.PKG}")
    print(f"modules over 500 lines: {len(f['over_500_lines'])}")
    for line in f["over_500_lines"]:
        print("   ", line)
    print(f"import circles: {len(f['circles'])} {f['circles'] or ''}")
    print(f"upward arrows: {len(f['upward'])} {f['upward'] or ''}")
    print(f"underscored names imported from another module: {len(f['private_imports'])}")
    for line in f["private_imports"]:
        print("   ", line)
    print(f"places defining the verdict vocabulary ('certified'): {len(f['verdict_definitions'])}")
    for line in f["verdict_definitions"]:
        print("   ", line)
    for key, title in (("arrows_back_up", "arrows that run back up (against docs/architecture.md's layer table)"),
                       ("side_doors", "side-door functions (public certificate entries outside certify.api)"),
                       ("literal_verdict_comparisons", "literal verdict comparisons")):
        items = f[key]
        assert isinstance(items, list)
        print(f"{title}: {len(items)}")
        for line in items:
            print("   ", line)
    print(f"test files: {f['test_files_flat']} flat, {f['test_files_in_folders']} in folders")


if __name__ == "__main__":
    main()
