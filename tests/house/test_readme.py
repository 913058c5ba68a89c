"""The README's two commands, and .ci/run running exactly the test one."""

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _bash_blocks():
    return re.findall(r"```bash\n(.*?)```", (ROOT / "README.md").read_text(), re.S)


def test_readme_opens_with_the_two_commands():
    blocks = _bash_blocks()
    assert "stringstab demo" in blocks[0]
    assert "pytest" in blocks[1]
    for b in blocks[:2]:
        assert "python3 -m venv" in b


def test_ci_runs_the_readme_test_command():
    test_cmd = _bash_blocks()[1].strip()
    ci = [ln for ln in (ROOT / ".ci" / "run").read_text().splitlines()
          if ln.strip() and not ln.startswith("#") and not ln.startswith(("set ", "cd "))]
    assert ci == [test_cmd]
    # the suite's slowest 15 tests are printed in CI (issue 32)
    assert "--durations=15" in test_cmd.split()
