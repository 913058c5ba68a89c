"""The documentation site cannot go stale: it builds strictly (no warning, no broken link or
anchor), its command-line reference is the parsers', and its Python examples run.

``mkdocs build --strict`` needs the ``docs`` extra (mkdocs, mkdocs-material,
mkdocstrings-python); the test is skipped, saying so, where it is not installed.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
BLOCK = re.compile(r"(<!-- docs-test: skip \((.*?)\) -->\n)?```python\n(.*?)```", re.S)


def test_mkdocs_builds_strictly(tmp_path):
    pytest.importorskip("mkdocs", reason="the docs extra (pip install -e '.[docs]') is not installed")
    pytest.importorskip("mkdocstrings_handlers.python", reason="mkdocstrings-python is not installed")
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}
    r = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "-q", "-f",
                        str(ROOT / "mkdocs.yml"), "-d", str(tmp_path / "site")],
                       capture_output=True, text=True, cwd=ROOT, env=env, timeout=600)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    for page in ("index.html", "quickstart/index.html", "cli/index.html", "api/index.html"):
        assert (tmp_path / "site" / page).is_file(), page
    api = (tmp_path / "site" / "api" / "index.html").read_text(encoding="utf-8")
    assert "Parameters" in api and "certify_batch" in api  # generated from the docstrings
    # docs/griffe_rst.py: Sphinx roles rendered (links), never shown as ":mod:`stringstab.derive`";
    # the .. math:: blocks typeset as embedded SVG, no TeX left
    assert not re.search(r":(?:mod|func|class|data|meth|attr|exc|obj|math):`", api)
    assert api.count('class="autorefs autorefs-internal"') >= 50
    assert 'class="math"' in api and "data:image/svg+xml;base64," in api
    text = re.sub(r"<[^>]+>", "", api)  # what a reader sees (the images' alt text is the TeX)
    assert "\\frac" not in text and "\\Gamma" not in text


def test_cli_reference_is_current():
    import runpy

    cli_reference = runpy.run_path(str(DOCS / "gen_cli.py"))["cli_reference"]
    assert (DOCS / "cli.md").read_text(encoding="utf-8") == cli_reference(), (
        "docs/cli.md is stale: python docs/gen_cli.py > docs/cli.md")


def test_every_nav_page_exists_and_every_page_is_in_the_nav():
    nav = re.findall(r":\s*([\w-]+\.md)\s*$", (ROOT / "mkdocs.yml").read_text(), re.M)
    pages = sorted(p.name for p in DOCS.glob("*.md"))
    assert sorted(nav) == pages


def _examples():
    for page in sorted(DOCS.glob("*.md")):
        blocks = BLOCK.findall(page.read_text(encoding="utf-8"))
        if blocks:
            yield pytest.param(page.name, blocks, id=page.stem)


@pytest.mark.parametrize(("page", "blocks"), list(_examples()))
def test_python_examples_run(page, blocks, tmp_path, monkeypatch):
    """Each page's ``python`` blocks run in order in one namespace (in a temporary folder);
    a block marked ``<!-- docs-test: skip (reason) -->`` is not run and must say why."""
    import matplotlib

    matplotlib.use("Agg")
    monkeypatch.chdir(tmp_path)
    ns: dict = {"__name__": f"docs.{page}"}
    ran = 0
    for marker, reason, code in blocks:
        if marker:
            assert reason.strip(), f"{page}: a skipped example must say why"
            continue
        exec(compile(code, f"docs/{page}", "exec"), ns)
        ran += 1
    import matplotlib.pyplot as plt

    plt.close("all")
    assert ran or all(m for m, _, _ in blocks)
