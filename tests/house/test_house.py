"""The house: no import cycle, no upward import, and a light start.

The import graph is read from the source (``ast``), so it includes the imports made inside
functions (lazy imports), which Python would otherwise only reveal at run time.  An edge
A → B means module A names module B in an ``import`` statement run at run time (imports for
type hints only, under ``if TYPE_CHECKING:``, are not edges).  Importing a submodule also
runs its parents' ``__init__`` (``import a.b.c`` imports ``a`` and ``a.b`` first), so an
edge A → ``a.b.c`` brings the edges A → ``a.b`` and A → ``a``, except to the packages that
contain A (already being imported when A runs).  *Upward* means a module importing a
package that contains it (the façade at the top re-exports the layers below, so a layer
importing it reaches over its own head); the package's version string therefore lives in
``stringstab/_version.py``, below every layer, and the ``__init__`` re-exports it.
"""

from __future__ import annotations

import ast
import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

PKG = Path(__file__).resolve().parents[2] / "stringstab"
ROOT = "stringstab"
#: Modules no numeric command may import at start-up.
HEAVY = ("sympy", "matplotlib", "casadi", "control", "gymnasium", "torch")
#: Upward imports still to remove (the test fails when one is gone, so the list is trimmed).
KNOWN_UPWARD: set[tuple[str, str]] = set()
#: Library modules that still run the command line (helper B: "the demo calls the library,
#: not the CLI"); strict in the same way.
KNOWN_CLI_USERS: set[str] = set()


def _modules() -> dict[str, Path]:
    out = {}
    for path in PKG.rglob("*.py"):
        rel = path.relative_to(PKG.parent).with_suffix("")
        parts = list(rel.parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


MODULES = _modules()


def _is_package(name: str) -> bool:
    return MODULES.get(name, Path()).name == "__init__.py"


def _resolve(module: str, level: int, target: str | None) -> str:
    if level == 0:
        return target or ""
    base = module.split(".")
    if not _is_package(module):
        base = base[:-1]
    base = base[: len(base) - (level - 1)]
    return ".".join(base + ([target] if target else []))


def _runtime_nodes(tree: ast.AST) -> list[ast.AST]:
    """Every node, except inside ``if TYPE_CHECKING:`` (imports for type hints only)."""
    out: list[ast.AST] = []
    todo = [tree]
    while todo:
        node = todo.pop()
        out.append(node)
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            todo.extend(node.orelse)
            continue
        todo.extend(ast.iter_child_nodes(node))
    return out


def imports_of(mod: str, nodes: list[ast.AST]) -> list[tuple[str, int]]:
    """(package module, line) for each module of the package named by an import among ``nodes``.

    ``import a.b.c`` names the longest prefix that is a module; ``from a.b import x`` names
    ``a.b.x`` when it is a module (a submodule), else ``a.b`` (a name defined in ``a.b``).
    """
    out: list[tuple[str, int]] = []
    for node in nodes:
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name == ROOT or alias.name.startswith(ROOT + "."):
                    name = alias.name
                    while name not in MODULES and "." in name:
                        name = name.rsplit(".", 1)[0]
                    if name != ROOT or alias.name == ROOT:  # else: not (yet) in the tree
                        out.append((name, node.lineno))
        elif isinstance(node, ast.ImportFrom):
            base = _resolve(mod, node.level, node.module)
            if not (base == ROOT or base.startswith(ROOT + ".")):
                continue
            for alias in node.names:
                sub = f"{base}.{alias.name}"
                # "from .pkg import submodule" imports the submodule; a name from pkg
                # imports pkg itself
                out.append((sub if sub in MODULES else base, node.lineno))
    return [(t, line) for t, line in out if t in MODULES]


def import_graph() -> dict[str, set[str]]:
    """Module → the package modules it imports (explicit imports anywhere in the file)."""
    graph: dict[str, set[str]] = {m: set() for m in MODULES}
    for mod, path in MODULES.items():
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        graph[mod] = {t for t, _ in imports_of(mod, _runtime_nodes(tree))}
    for mod in graph:
        graph[mod] |= {p for t in graph[mod] for p in _implicit_parents(mod, t)}
        graph[mod].discard(mod)
    return graph


def _implicit_parents(mod: str, target: str) -> set[str]:
    """The packages that importing ``target`` from ``mod`` also imports: its parents.

    Importing ``a.b.c`` runs ``a/__init__`` and ``a/b/__init__`` first.  The parents that
    contain ``mod`` itself are left out: they are already being imported when ``mod`` runs
    (``stringstab.regions.grid`` importing ``stringstab.io`` does not run ``stringstab``
    again), so they add no step.
    """
    parts = target.split(".")
    parents = {".".join(parts[:i]) for i in range(1, len(parts))}
    return {p for p in parents if p in MODULES and not mod.startswith(p + ".")}


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []
    counter = [0]

    def visit(v: str) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    sys.setrecursionlimit(10_000)
    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def upward(graph: dict[str, set[str]]) -> set[tuple[str, str]]:
    return {(m, t) for m, targets in graph.items() for t in targets
            if _is_package(t) and m.startswith(t + ".")}


def test_the_graph_sees_lazy_and_relative_imports():
    g = import_graph()
    assert "stringstab.certify.criteria" in g["stringstab.certify.continuous"]  # top-level relative import
    assert "stringstab.derive.errata" in g["stringstab.derive.derivation"]  # inside derivation()
    assert "stringstab.derive.symbolic" in g["stringstab.derive.codegen"]  # "from . import symbolic as S"
    assert "stringstab.regions.report" in g["stringstab.regions.result"]
    assert "stringstab.tuning.projection" in g["stringstab.tuning"]  # from .projection import
    # implicit parents: "from .io.gains import ..." in the façade also runs io/__init__ ...
    assert {"stringstab.io.gains", "stringstab.io"} <= g["stringstab"]
    # ... but not the packages containing the importer, already being imported
    assert _implicit_parents("stringstab.regions.grid", "stringstab.io.outputs") == {"stringstab.io"}
    assert _implicit_parents("stringstab.cli.tune", "stringstab.plots.tuning") == {"stringstab.plots"}
    assert _implicit_parents("stringstab.plots.tuning", "stringstab.plots._common") == set()
    # the checks below can fail: a made-up cycle and upward import are found
    fake = {**g, "stringstab.certify.margin": g["stringstab.certify.margin"] | {"stringstab.certify.continuous"}}
    assert any("stringstab.certify.margin" in c for c in cycles(fake))
    fake = {**g, "stringstab.certify.margin": g["stringstab.certify.margin"] | {"stringstab"}}
    assert ("stringstab.certify.margin", "stringstab") in upward(fake)


def test_no_import_cycle():
    assert cycles(import_graph()) == []


def test_no_upward_import():
    found = upward(import_graph())
    assert found - KNOWN_UPWARD == set(), "upward imports"
    assert KNOWN_UPWARD - found == set(), "fixed: remove them from KNOWN_UPWARD"


ARCHITECTURE = PKG.parent / "docs" / "architecture.md"


def layer_table(text: str) -> list[tuple[str, tuple[str, ...]]]:
    """The layer table of ``docs/architecture.md``, bottom layer first: (layer, module names).

    Read from the rows ``| # | layer | modules | ... |`` of the section "## Layers"; the
    module names are the backticked dotted names of the ``modules`` column.
    """
    section = text.split("\n## Layers\n", 1)[1].split("\n## ", 1)[0]
    rows = []
    for line in section.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) >= 3 and cells[0].isdigit():
            names = tuple(n for n in re.findall(r"`([\w.]+)`", cells[2])
                          if n == ROOT or n.startswith(ROOT + "."))
            rows.append((int(cells[0]), cells[1], names))
    assert [r[0] for r in rows] == list(range(len(rows))), "layers numbered 0, 1, 2, ... from the bottom"
    return [(name, names) for _, name, names in rows]


def layer_of(mod: str, table: list[tuple[str, tuple[str, ...]]]) -> tuple[int, str] | None:
    """(number, name) of the layer holding ``mod``: the longest name of the table that is
    ``mod`` or a package containing it (the root ``stringstab`` stands for the façade only)."""
    best: tuple[int, int, str] | None = None
    for i, (layer, names) in enumerate(table):
        for n in names:
            if mod == n or (n != ROOT and mod.startswith(n + ".")):
                if best is None or len(n) > best[0]:
                    best = (len(n), i, layer)
    return None if best is None else (best[1], best[2])


def layer_violations(sources: dict[str, tuple[str, str]],
                     table: list[tuple[str, tuple[str, ...]]]) -> list[str]:
    """Every import of a module in a higher layer, one line each: file, line, both layers.

    ``sources`` maps a module name to (its file, its source).  Every import counts: at
    module level, inside a function, or under ``if TYPE_CHECKING:``.
    """
    out = []
    for mod, (file, text) in sorted(sources.items()):
        here = layer_of(mod, table)
        if here is None:
            out.append(f"{file}: {mod} is in no layer of docs/architecture.md")
            continue
        nodes = list(ast.walk(ast.parse(text, filename=file)))
        for target, line in sorted(set(imports_of(mod, nodes)), key=lambda e: (e[1], e[0])):
            there = layer_of(target, table)
            if there is not None and there[0] > here[0]:
                out.append(f"{file}:{line}: {mod} (layer {here[0]}, {here[1]}) imports {target} "
                           f"(layer {there[0]}, {there[1]}), a higher layer")
    return out


def _package_sources() -> dict[str, tuple[str, str]]:
    return {mod: (str(path.relative_to(PKG.parent)), path.read_text(encoding="utf-8"))
            for mod, path in MODULES.items()}


def test_the_imports_obey_the_layer_table():
    table = layer_table(ARCHITECTURE.read_text(encoding="utf-8"))
    found = layer_violations(_package_sources(), table)
    assert found == [], "imports climbing a layer of docs/architecture.md:\n" + "\n".join(found)


def test_the_layer_table_places_every_module_once():
    table = layer_table(ARCHITECTURE.read_text(encoding="utf-8"))
    names = [n for _, ns in table for n in ns]
    assert len(names) == len(set(names)), "a name in two layers"
    assert set(names) <= set(MODULES), "names in the table that are no module of the package"
    assert [m for m in MODULES if layer_of(m, table) is None] == []
    # the root name stands for the façade only: a new root module must be placed by name
    assert layer_of("stringstab.newmodule", table) is None
    assert layer_of("stringstab.certify.api", table) == (3, "certificates")


def test_the_layer_check_fails_on_a_planted_upward_import():
    table = layer_table(ARCHITECTURE.read_text(encoding="utf-8"))
    sources = _package_sources()
    # plant, in a copy of the sources (the package is not edited), an import of the
    # certificates into the formulas: at module level, inside a function, relative and absolute
    file, text = sources["stringstab.derive.errata"]
    sources["stringstab.derive.errata"] = (file, text + (
        "\n\ndef _planted():\n    from ..certify.criteria import psi\n    return psi\n"))
    line = len(text.splitlines()) + 4
    sources["stringstab.io.planted"] = ("stringstab/io/planted.py",
                                        '"""Planted."""\nimport stringstab.traffic.platoon\n')
    sources["stringstab.plots.planted"] = ("stringstab/plots/planted.py",
                                           "from stringstab import certify\nfrom .. import cli\n")
    found = layer_violations(sources, table)
    assert found == [
        f"stringstab/derive/errata.py:{line}: stringstab.derive.errata (layer 2, formulas) imports "
        "stringstab.certify.criteria (layer 3, certificates), a higher layer",
        "stringstab/io/planted.py:2: stringstab.io.planted (layer 1, files) imports "
        "stringstab.traffic.platoon (layer 6, platoons), a higher layer",
        "stringstab/plots/planted.py:2: stringstab.plots.planted (layer 5, figures) imports "
        "stringstab.cli (layer 10, entry points), a higher layer",
    ]
    # the façade is the top layer: importing a name from it climbs too
    sources = {"stringstab.tuning.planted": ("p.py", "from stringstab import Params\n")}
    assert layer_violations(sources, table) == [
        "p.py:1: stringstab.tuning.planted (layer 4, maps and tuning) imports stringstab "
        "(layer 10, entry points), a higher layer"]
    # a module placed in no layer is reported too
    sources = {"stringstab.newmodule": ("stringstab/newmodule.py", "")}
    assert layer_violations(sources, table) == [
        "stringstab/newmodule.py: stringstab.newmodule is in no layer of docs/architecture.md"]


def test_no_library_module_imports_the_cli_or_the_demo():
    users = set()
    for mod, targets in import_graph().items():
        if mod.startswith(("stringstab.cli", "stringstab.__main__")):
            continue
        if any(t.startswith("stringstab.cli") or t == "stringstab.cli.demo_steps" for t in targets):
            users.add(mod)
    assert users - KNOWN_CLI_USERS == set(), "library modules importing the CLI"
    assert KNOWN_CLI_USERS - users == set(), "fixed: remove them from KNOWN_CLI_USERS"


def _heavy_after(code: str, heavy: tuple[str, ...] = HEAVY) -> list[str]:
    script = (f"import sys, json\n{code}\n"
              f"print(json.dumps([m for m in {heavy!r} if m in sys.modules]))")
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         check=True, timeout=120)
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_certify_loads_no_heavy_module():
    assert _heavy_after(
        "import stringstab\n"
        "c = stringstab.certify(1, 0.5, 0.5, tau=0.1, delta=0.2, headway=1.1)\n"
        "b = stringstab.certify_batch([1, 0.9], [0.5, -0.5], [0.5, 1.1], tau=0.1, delta=0.2,"
        " headway=1.1)\n"
        "t = stringstab.taylor_criteria(1, 0.5, 0.5, tau=0.1, delta=0.2, headway=1.1)\n"
        "assert c.verdict == 'certified'") == []


@pytest.mark.parametrize("module", ["stringstab.certify.margin", "stringstab.regions", "stringstab.tuning",
                                    "stringstab.plots"])
def test_numeric_modules_load_no_heavy_module(module):
    assert _heavy_after(f"import {module}") == []


def test_cli_certify_loads_no_heavy_module():
    assert _heavy_after(
        "import contextlib, io\n"
        "from stringstab.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        "    assert main(['certify', '1,0.5,0.5']) == 0") == []


#: The certificates of other loops, imported only when a caller asks for them: the sampled
#: loop (its certificate and the modules of its arithmetic) and the robust one (the way in,
#: the continuous box and the sampled box).
SAMPLED_LOOP = ("stringstab.certify.sampled", "stringstab.certify.zoh", "stringstab.certify.interval",
                "stringstab.certify.point_program", "stringstab.certify.schur",
                "stringstab.certify.sampled_curvature", "stringstab.certify.sampled_frequency",
                "stringstab.certify.sampled_excess")
OTHER_LOOPS = (*SAMPLED_LOOP, "stringstab.certify.robust", "stringstab.certify.robust_continuous",
               "stringstab.certify.robust_sampled", "stringstab.derive.sampled_symbolic")


def test_the_continuous_certificate_loads_neither_the_sampled_nor_the_robust_one():
    code = ("import contextlib, io\n"
            "import stringstab\n"
            "from stringstab.cli import main\n"
            "stringstab.certify(1, 0.5, 0.5, tau=0.1, delta=0.2, headway=1.1)\n"
            "stringstab.check([1], [0.5], [0.5], tau=0.1, delta=0.2, headway=1.1)\n"
            "with contextlib.redirect_stdout(io.StringIO()):\n"
            "    assert main(['certify', '1,0.5,0.5']) == 0\n")
    assert _heavy_after(code, OTHER_LOOPS) == []
    # the check above can fail: asking for the sampled loop loads it (and no heavy module)
    sampled = code + "stringstab.certify(1, 0.5, 0.5, tau=0.1, delta=0.2, headway=1.1, sample_time=0.1)\n"
    assert _heavy_after(sampled, OTHER_LOOPS) == list(SAMPLED_LOOP)
    # a box of the continuous loop loads none of the sampled loop's arithmetic
    robust = code + "stringstab.certify(1, 0.5, 0.5, tau=(0.1, 0.2), delta=0.2, headway=1.1)\n"
    assert _heavy_after(robust, OTHER_LOOPS) == ["stringstab.certify.robust",
                                                 "stringstab.certify.robust_continuous"]
    assert _heavy_after(robust) == []
    box = robust + ("stringstab.certify(1, 0.5, 0.5, tau=(0.1, 0.2), delta=0.2, headway=1.1,"
                    " sample_time=0.1)\n")
    assert "stringstab.certify.robust_sampled" in _heavy_after(box, OTHER_LOOPS)


#: The package root: the façade and the shared basics; every other module lives in a
#: subpackage whose ``__init__`` says what is there.
ROOT_MODULES = {"__init__.py", "__main__.py", "_version.py", "ranges.py",
                "constants.py", "errors.py", "progress.py", "memory.py"}


def test_the_root_holds_the_facade_and_the_shared_basics_only():
    assert {p.name for p in PKG.glob("*.py")} == ROOT_MODULES


def test_every_subpackage_says_what_lives_there():
    for init in PKG.rglob("__init__.py"):
        doc = ast.get_docstring(ast.parse(init.read_text(encoding="utf-8")))
        assert doc and len(doc) > 80, f"{init.relative_to(PKG.parent)} has no docstring saying what lives there"


#: "No module over ~500 lines doing more than one job": a module over :data:`LONG` lines is
#: listed here with its one job (the test fails when one is added unlisted, or shrinks).
LONG = 500
LONG_MODULES = {
    "stringstab/certify/sampled_split_cells.py": ("the split form's cells: bounds of F and G over "
                                                  "cells, and the cells computed ahead"),
    "stringstab/tuning/constraints.py": "the projection's constraints for any loop, as quadratic forms in K",
    "stringstab/tuning/projector.py": "the Projector: nearest certified gains for one loop, cached and warm-started",
    "stringstab/tuning/repair.py": "the IDL repair step (§3.3) of a training loop: GainRepair",
    "stringstab/certify/api.py": ("the one way in to every certificate: Loop and the façade "
                                  "(certify, certify_batch, check, certify_string), mostly docstrings"),
    "stringstab/regions/result.py": "RegionMap, the result of a region map, with its files",
    "stringstab/derive/symbolic.py": "the symbolic derivation of Γ(s), Ψ1–Ψ3 and Λ",
    "stringstab/identify/estimate.py": "one follower's estimate: fit, certificate, bootstrap, profiles",
    "stringstab/cli/platoon.py": "the `stringstab platoon` command: head-to-tail verdicts of recorded strings",
    "stringstab/certify/continuous.py": "the exact continuous-time certificate: its results and kernels",
    "stringstab/certify/zoh.py": "the zero-order-hold discretisation: the coefficients of H(z) and of g_H",
    "stringstab/report/commands.py": "the reports of the commands that write a folder",
    "stringstab/traffic/dynamics.py": "the platoon's stepping core, many platoons at once",
    "stringstab/certify/lifted_frequency.py": "proven bounds on λ_min of the lifted link's margin M(θ)",
    "stringstab/identify/fit.py": "the closed-loop simulation-error fit of the eq-4 law to one record",
    "stringstab/cli/sumo.py": "the `stringstab sumo` command: the controllers inside Eclipse SUMO",
    "stringstab/rl/train.py": "the training loop: train(config) -> TrainResult, resumable",
    "stringstab/rl/config.py": "the trainer's configuration: IDL Table 1 as defaults, one field per choice",
    "stringstab/io/outputs.py": "output files and folders, checked first and written all-or-nothing",
    "stringstab/derive/codegen.py": "the generator of derive/generated.py, the numeric code of every formula",
    "stringstab/certify/robust_split.py": "the branch and bound of the split margin F − G ≥ 0 over cells",
    "stringstab/certify/head_to_tail.py": "the head-to-tail certificate of heterogeneous strings",
    "stringstab/hcfs/theorem.py": "the HCFS jerk theorem as a checkable statement, and its bound",
    "stringstab/io/platoon_logs.py": "the readers of recorded platoons (OpenACC, plain CSV, NGSIM), in SI units",
    "stringstab/certify/criteria.py": "the vectorised criteria: Hurwitz, Proposition 1 and the types I-IV",
    "stringstab/certify/multirate.py": "the certificate of the multi-rate V2V loop",
    "stringstab/report/render.py": "the report's model (Report, Section) and its one renderer",
    "stringstab/traffic/metrics.py": "the IDL paper's evaluation metrics (§4.2)",
}


def test_long_modules_do_one_job():
    long = {str(p.relative_to(PKG.parent)) for p in PKG.rglob("*.py")
            if len(p.read_text(encoding="utf-8").splitlines()) > LONG
            and p.name != "generated.py"}  # written by stringstab.derive.codegen
    assert long - set(LONG_MODULES) == set(), f"modules over {LONG} lines: split them by job"
    assert set(LONG_MODULES) - long == set(), "no longer long: remove them from LONG_MODULES"


def _private_imports() -> set[tuple[str, str]]:
    """(importer, "module.name") for every underscored name imported from another module."""
    out = set()
    for mod, path in MODULES.items():
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom):
                base = _resolve(mod, node.level, node.module)
                if base.startswith(ROOT) and base != mod:
                    out |= {(mod, f"{base}.{a.name}") for a in node.names
                            if a.name.startswith("_") and not a.name.startswith("__")}
                    # a private module of another package (its own package's are its business;
                    # _version is the version's one home, below every layer)
                    parent, _, last = base.rpartition(".")
                    if (last.startswith("_") and not last.startswith("__")
                            and base != f"{ROOT}._version" and mod != parent
                            and not mod.startswith(parent + ".")):
                        out.add((mod, base))
    return out


#: Underscored names still imported across modules (the test fails when one is gone).
KNOWN_PRIVATE_IMPORTS: set[tuple[str, str]] = set()


def test_no_underscored_name_is_imported_from_another_module():
    found = _private_imports()
    assert found - KNOWN_PRIVATE_IMPORTS == set(), "private names imported across modules"
    assert KNOWN_PRIVATE_IMPORTS - found == set(), "fixed: remove them from KNOWN_PRIVATE_IMPORTS"


def test_stringstab_certify_stays_the_function():
    # the façade binds the name to the function of the subpackage of the same name; importing
    # every module of that subpackage must not rebind it to the subpackage
    code = ("import importlib, pkgutil, inspect, sys, stringstab\n"
            "pkg = sys.modules['stringstab.certify']\n"
            "for m in pkgutil.iter_modules(pkg.__path__):\n"
            "    importlib.import_module('stringstab.certify.' + m.name)\n"
            "import stringstab.derive.errata\n"
            "assert inspect.isfunction(stringstab.certify), stringstab.certify\n"
            "assert stringstab.certify(1, 0.5, 0.5, tau=0.1, delta=0.2, headway=1.1).verdict\n")
    subprocess.run([sys.executable, "-c", code], check=True, timeout=120)


def test_no_source_reaches_certify_modules_through_the_function():
    # "import stringstab.certify.x as m" and "stringstab.certify.x.f" look up the attribute
    # ``certify`` of the package, which is the function: both fail at run time
    bad = re.compile(r"^\s*import stringstab\.certify\.\w+ as |(?<![\w.`:])stringstab\.certify\.\w+\.\w+\(")
    roots = [PKG, PKG.parent / "tests", PKG.parent / "analysis"]
    hits = [f"{p}:{i}" for r in roots if r.exists() for p in r.rglob("*.py")
            for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1)
            if bad.search(line) and p.name != "test_house.py"]
    assert hits == []


def _defined_names(tree: ast.Module) -> set[str]:
    """Names a module defines at module level: def, class, assignment (also inside ``if``/``try``)."""
    names: set[str] = set()

    def visit(body: list[ast.stmt]) -> None:
        for node in body:
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                names.add(node.name)
            elif isinstance(node, ast.Assign):
                names.update(n.id for t in node.targets for n in ast.walk(t) if isinstance(n, ast.Name))
            elif isinstance(node, (ast.AnnAssign, ast.AugAssign)) and isinstance(node.target, ast.Name):
                names.add(node.target.id)
            elif isinstance(node, ast.If):
                visit(node.body)
                visit(node.orelse)
            elif isinstance(node, ast.Try):
                for part in (node.body, node.orelse, node.finalbody, *(h.body for h in node.handlers)):
                    visit(part)

    visit(tree.body)
    return names


def _reexports(source: str) -> list[str]:
    """Names in a module's ``__all__`` that it does not define (imports it re-exports)."""
    tree = ast.parse(source)
    listed: list[str] = []
    for node in tree.body:
        targets = node.targets if isinstance(node, ast.Assign) else (
            [node.target] if isinstance(node, ast.AnnAssign) else [])
        if any(isinstance(t, ast.Name) and t.id == "__all__" for t in targets):
            assert node.value is not None
            listed = list(ast.literal_eval(node.value))
    return [name for name in listed if name not in _defined_names(tree)]


def test_a_module_exports_only_what_it_defines():
    # one home per name: a module (not a package ``__init__``, which re-exports its modules
    # by design) lists in ``__all__`` only names it defines, so no module is a re-export shim
    shims = {mod: names for mod, path in MODULES.items()
             if path.name != "__init__.py" and (names := _reexports(path.read_text(encoding="utf-8")))}
    assert shims == {}, "modules re-exporting names defined elsewhere"
    # the check can fail: a made-up shim is found; definitions in if/try and assignments count
    fake = ("from .limits import Limits\nimport numpy as np\n"
            "__all__ = ['Limits', 'np', 'simulate', 'A', 'B', 'C', 'D']\n"
            "def simulate(): ...\nA: int = 1\nif True:\n    B = 2\nelse:\n    C = 3\n"
            "try:\n    from x import D\nexcept ImportError:\n    D = None\n")
    assert _reexports(fake) == ["Limits", "np"]
