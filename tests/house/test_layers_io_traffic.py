"""Layering of the I/O home, the simulator and the metrics: nothing imports upwards.

Checked on the source (every import statement, including those inside functions):
``stringstab.io`` uses only ``stringstab.errors`` (and ``stringstab._version``); the metrics and
the simulator never import the command line or the demo; the metrics never import the
simulator (``PlatoonResult.metrics()`` calls ``metrics.platoon_metrics``, not the reverse).
"""

import ast
from pathlib import Path

import pytest

PKG = Path(__file__).resolve().parents[2] / "stringstab"


def _imports(path: Path) -> set[str]:
    """Absolute names of the stringstab modules imported by ``path``."""
    mod = ".".join(path.relative_to(PKG.parent).with_suffix("").parts)
    package = mod.rsplit(".", 1)[0] if path.name != "__init__.py" else mod
    out = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                name = ".".join(base + ([node.module] if node.module else []))
            else:
                name = node.module or ""
            out.add(name)
            out.update(f"{name}.{a.name}" for a in node.names)
        elif isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
    return {n for n in out if n == "stringstab" or n.startswith("stringstab.")}


def _files(*parts: str) -> list[Path]:
    out = []
    for p in parts:
        q = PKG / p
        out += sorted(q.rglob("*.py")) if q.is_dir() else [q]
    return out


@pytest.mark.parametrize("path", _files("io"), ids=lambda p: p.name)
def test_io_is_the_bottom_layer(path):
    allowed = ("stringstab.io", "stringstab.errors", "stringstab._version")
    bad = {n for n in _imports(path) if not n.startswith(allowed)}
    assert not bad, f"{path.name} imports {sorted(bad)}"


@pytest.mark.parametrize("path", _files("traffic", "params", "constants.py", "errors.py"), ids=lambda p: p.name)
def test_no_import_of_the_cli_or_the_demo(path):
    bad = {n for n in _imports(path) if n.startswith("stringstab.cli")}
    assert not bad, f"{path} imports {sorted(bad)}"


def test_metrics_do_not_import_the_simulator():
    assert not {n for n in _imports(PKG / "traffic" / "metrics.py") if n.startswith("stringstab.traffic")}
