"""The CLI registers sub-commands lazily: one command imports only its own module."""

import argparse
import importlib
import subprocess
import sys

import pytest

from stringstab.cli import COMMANDS, HELP, build_parser, main


@pytest.mark.parametrize("name", sorted(HELP))
def test_static_help_is_what_the_module_registers(name):
    assert name in COMMANDS
    mod = importlib.import_module(f"stringstab.cli.{name}")
    sub = argparse.ArgumentParser().add_subparsers()
    mod.add_parser(sub)
    (action,) = sub._choices_actions
    assert action.help == HELP[name]


def test_lazy_parser_lists_every_command(capsys):
    full = build_parser()
    lazy = build_parser(lazy=True)
    assert lazy.format_help() == full.format_help()
    with pytest.raises(SystemExit) as e:
        main(["nope"])
    assert e.value.code == 2
    assert "invalid choice: 'nope'" in capsys.readouterr().err


def test_certify_imports_only_what_it_uses():
    """A subprocess (a fresh interpreter): no other command, no plotting, simulator or writer."""
    code = (
        "import sys\n"
        "from stringstab.cli import main\n"
        "assert main(['certify', '1,0.5,0.5']) == 0\n"
        "heavy = ['stringstab.cli.derive', 'stringstab.cli.region', 'stringstab.cli.tune',\n"
        "         'stringstab.cli.simulate', 'stringstab.cli.demo', 'stringstab.traffic',\n"
        "         'stringstab.tuning', 'stringstab.regions', 'matplotlib', 'gymnasium',\n"
        "         'casadi', 'pyarrow', 'tqdm', 'control']\n"
        "loaded = [m for m in heavy if m in sys.modules]\n"
        "assert not loaded, loaded\n"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert "certified" in r.stdout
