"""The command-line reference (``docs/cli.md``), generated from the argparse parsers.

A script beside the pages (not part of the package): ``python docs/gen_cli.py > docs/cli.md``
regenerates the page, and a test (tests/docs/test_docs_site.py) checks that the page is current.  Each command's description and every argument
(flags, value, default, help) are read from the parser the ``stringstab`` command itself uses,
so the page cannot drift from the tool; the text does not depend on the Python version or the
terminal width (argparse's own ``--help`` layout does).
"""

from __future__ import annotations

import argparse
from typing import Any

__all__ = ["cli_reference"]


def _subparsers(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    for a in parser._actions:
        if isinstance(a, argparse._SubParsersAction):
            return dict(a.choices)
    return {}


def _cell(text: Any) -> str:
    return " ".join(str(text).split()).replace("|", "\\|")


def _flags(a: argparse.Action) -> str:
    if not a.option_strings:
        return f"`{a.metavar or a.dest}`".replace("|", "\\|")
    value = ""
    if a.nargs != 0:
        value = " " + (a.metavar if isinstance(a.metavar, str) else a.dest.upper())
        if a.nargs in ("+", "*"):
            value += " ..."
    return ", ".join(f"`{o}{value}`" for o in a.option_strings).replace("|", "\\|")


def _help(a: argparse.Action) -> str:
    text = a.help or ""
    if "%(" in text:
        text = text % {"default": a.default, "prog": "stringstab", "dest": a.dest}
    if a.choices is not None and not isinstance(a, argparse._SubParsersAction):
        text += f" (one of: {', '.join(map(str, a.choices))})"
    return _cell(text)


def _section(name: str, p: argparse.ArgumentParser, level: int, out: list[str]) -> None:
    out.append(f"{'#' * level} `stringstab {name}`\n")
    if p.description:
        out.append(_cell(p.description) + "\n")
    rows = [a for a in p._actions if not isinstance(a, (argparse._HelpAction,
                                                           argparse._SubParsersAction))
            and a.help != argparse.SUPPRESS]
    if rows:
        out.append("| argument | what it is |\n|---|---|")
        out += [f"| {_flags(a)} | {_help(a)} |" for a in rows]
        out.append("")
    for sub_name, sub in _subparsers(p).items():
        _section(f"{name} {sub_name}", sub, level + 1, out)


def cli_reference() -> str:
    """The Markdown page of every command and argument of ``stringstab``.

    Returns
    -------
    str
        The page (``docs/cli.md``).
    """
    from stringstab.cli import COMMANDS, HELP, build_parser

    parser = build_parser()
    subs = _subparsers(parser)
    out = ["# Command-line reference\n",
           "Generated from the argument parsers of the `stringstab` command "
           "(`python docs/gen_cli.py > docs/cli.md`); `stringstab COMMAND --help` "
           "prints the same. Every command checks its inputs before it starts and answers bad "
           "input with one line on standard error and exit code 2.\n",
           "| command | what it does |\n|---|---|"]
    out += [f"| [`{c}`](#stringstab-{c}) | {_cell(HELP.get(c, ''))} |" for c in COMMANDS if c in subs]
    out.append("")
    for name in COMMANDS:
        if name in subs:
            _section(name, subs[name], 2, out)
    return "\n".join(out).rstrip() + "\n"


if __name__ == "__main__":  # pragma: no cover
    print(cli_reference(), end="")
