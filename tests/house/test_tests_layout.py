"""The tests' layout (issue 32, item 6): folders by capability, in one table.

Every test file lives in a folder of ``tests/`` (none at the top), every folder is a package
(``__init__.py``) named in the table of docs/architecture.md's section "The tests", and every
folder the table names exists.
"""

import re
from pathlib import Path

TESTS = Path(__file__).resolve().parents[1]
ARCHITECTURE = TESTS.parent / "docs" / "architecture.md"


def _table() -> list[str]:
    text = ARCHITECTURE.read_text(encoding="utf-8")
    section = text.split("\n## The tests\n", 1)[1].split("\n## ", 1)[0]
    return re.findall(r"^\| `tests/(\w+)/` \|", section, re.M)


def _folders() -> list[str]:
    return sorted(p.name for p in TESTS.iterdir()
                  if p.is_dir() and p.name != "data" and not p.name.startswith((".", "_")))


def test_no_test_file_at_the_top():
    assert sorted(p.name for p in TESTS.glob("test_*.py")) == []


def test_every_folder_is_a_package_in_the_table():
    table = _table()
    assert len(table) == len(set(table)) >= 10  # the table was found, each folder once
    assert _folders() == sorted(table)
    assert [f for f in table if not (TESTS / f / "__init__.py").is_file()] == []
    assert (TESTS / "__init__.py").is_file()
