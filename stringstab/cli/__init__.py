"""The ``stringstab`` command: a thin layer that parses, calls the library, prints.

Each sub-command lives in its own module of this package and exposes
``add_parser(subparsers)`` (which registers it and sets ``func``) and a
``run(args) -> int``.  Bad input (:class:`~stringstab.errors.StringStabError`)
becomes a one-line message on stderr and exit code 2; no verdict is printed.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence
from typing import Any

from .. import __version__
from ..errors import StringStabError

__all__ = ["COMMANDS", "build_parser", "main"]

#: Sub-command modules, in the order ``stringstab --help`` lists them.
COMMANDS: list[str] = [
    "derive",
    "certify",
    "region",
    "tune",
    "simulate",
    "train",
    "hcfs",
    "demo",
]


class _Parser(argparse.ArgumentParser):
    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        from ._common import NEGATIVE_NUMBER

        self._negative_number_matcher = NEGATIVE_NUMBER  # "-0.5,1,1" is a value

    def error(self, message: str) -> None:  # type: ignore[override]
        self.print_usage(sys.stderr)
        self.exit(2, f"{self.prog}: error: {message}\n")


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every available sub-command registered."""
    parser = _Parser(
        prog="stringstab",
        description="Exact, delay-aware string-stability analysis of car-following controllers.",
    )
    parser.add_argument("--version", action="version", version=f"stringstab {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for name in COMMANDS:
        try:
            mod = importlib.import_module(f"{__name__}.{name}")
        except ModuleNotFoundError as e:
            if e.name == f"{__name__}.{name}":
                continue  # command not built yet
            raise
        mod.add_parser(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``stringstab`` console script; returns the exit code."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except StringStabError as e:
        msg = str(e).replace("\n", " ")
        print(f"stringstab {args.command}: error: {msg}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # pragma: no cover - e.g. piped into head
        return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
