"""``stringstab demo``: run the whole pipeline on bundled data."""

from __future__ import annotations

import argparse
from typing import Any

__all__ = ["add_parser", "run"]


def add_parser(sub: Any) -> None:
    """Register ``demo``.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The ``stringstab`` sub-command set (:func:`stringstab.cli.build_parser`); the parser
        added sets ``func`` to :func:`run`.
    """
    from .demo_steps import STEPS

    p = sub.add_parser(
        "demo",
        help="run a demo of the whole pipeline on bundled data",
        description="Steps: " + ", ".join(name for name, _ in STEPS),
    )
    p.add_argument("--out", default="demo-out",
                   help="output directory (default: demo-out); an earlier demo's files in it are "
                        "replaced, and it is left untouched if the demo fails")
    p.add_argument("--only", action="append", metavar="STEP", help="run only this step (repeatable)")
    from ._common import add_limit_arguments

    add_limit_arguments(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run ``demo``.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of ``stringstab demo``.

    Returns
    -------
    int
        Exit code: 0 when the demo ran; bad input raises
        :class:`~stringstab.errors.StringStabError` (exit 2 from
        :func:`stringstab.cli.main`).
    """
    from ..errors import StringStabError, show
    from .demo_steps import STEPS, run_demo

    names = [n for n, _ in STEPS]
    for o in args.only or []:
        if o not in names:
            raise StringStabError(f"--only: unknown step {show(o)}; expected one of {names}")
    from ..report import command_line
    from ._common import limits_from_args

    run_demo(args.out, only=args.only, limits=limits_from_args(args), command=command_line(args))
    print(f"demo done: outputs in {args.out}/; open {args.out}/report.html (or report.md)")
    return 0
