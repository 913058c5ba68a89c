"""Project habits: one version, a licence that matches the metadata, a citation file."""

import re
from importlib import metadata
from pathlib import Path

import stringstab

ROOT = Path(__file__).resolve().parents[2]


def test_version_has_one_source():
    pyproject = (ROOT / "pyproject.toml").read_text()
    assert 'dynamic = ["version"]' in pyproject
    assert not re.search(r'^version\s*=\s*"', pyproject, re.M)  # no second copy
    assert 'attr = "stringstab._version.__version__"' in pyproject
    assert metadata.version("stringstab") == stringstab.__version__
    assert not re.search(r"^version:", (ROOT / "CITATION.cff").read_text(), re.M)


def test_licence_and_citation():
    assert (ROOT / "LICENSE").read_text().startswith("MIT License")
    assert 'license = { text = "MIT" }' in (ROOT / "pyproject.toml").read_text()
    cff = (ROOT / "CITATION.cff").read_text()
    assert "cff-version: 1.2.0" in cff and "license: MIT" in cff
    assert "doi: 10.1016/j.trc.2026.105541" in cff  # the IDL paper
    assert "Hybrid Car-Following Strategy Based on Deep Deterministic Policy Gradient" in cff
    assert (ROOT / "CHANGELOG.md").read_text().startswith("# Changelog")


def test_ci_lints_and_type_checks():
    ci = (ROOT / ".ci" / "run").read_text()
    assert "ruff check ." in ci and "/mypy" in ci and "pytest" in ci
    assert ci.index("ruff") < ci.index("mypy") < ci.index("pytest")
