"""The ``stringstab`` command: a thin layer that parses, calls the library, prints.

Each sub-command lives in its own module of this package and exposes
``add_parser(subparsers)`` (which registers it and sets ``func``) and a
``run(args) -> int``.  Bad input (:class:`~stringstab.errors.StringStabError`)
becomes a one-line message on stderr and exit code 2; no verdict is printed.  The
entry point is the one place that also turns Ctrl-C and SIGTERM (``KeyboardInterrupt``: one
line, exit 130) and ``MemoryError`` (one line, exit 2) into a sentence.

Sub-commands are registered lazily: ``stringstab --help`` lists them from
:data:`HELP` and ``stringstab NAME ...`` imports only ``stringstab.cli.NAME``,
so a quick command does not pay for the imports of the others (SymPy for
``derive``, matplotlib for ``region``, gymnasium for ``simulate``).
"""

from __future__ import annotations

import argparse
import importlib
import signal
import sys
import threading
from collections.abc import Sequence
from typing import Any

from .._version import __version__
from ..errors import StringStabError

__all__ = ["COMMANDS", "HELP", "build_parser", "main"]

#: Sub-command modules, in the order ``stringstab --help`` lists them.
COMMANDS: list[str] = [
    "derive",
    "certify",
    "region",
    "tune",
    "simulate",
    "radio",
    "train",
    "evaluate",
    "compare",
    "hcfs",
    "identify",
    "platoon",
    "sumo",
    "sweep",
    "demo",
]

#: One-line help of each sub-command, shown by ``stringstab --help`` without importing it
#: (tests check that each equals the help its module registers).  A command missing here
#: is imported to be listed.
HELP: dict[str, str] = {
    "derive": "derive Γ(s), Ψ1-Ψ3, Λ, gradients and Hurwitz conditions symbolically",
    "certify": "certify gain triples K = [k_x, k_v, k_a] as string stable (exact delay)",
    "region": "map the string-stable gains on a 2-D slice or a 3-D grid (figures + data)",
    "tune": "repair gain triples that are not string stable (region growing or projection)",
    "simulate": "simulate a platoon behind a leader; write trajectories, metrics JSON and figures",
    "radio": "measure a platoon's amplification with V2V message loss and noise (Monte Carlo)",
    "train": "train an IDL policy (TD3 emitting certified gains) or a pure TD3/DDPG baseline",
    "evaluate": "evaluate a trained policy on held-out leaders; certify every executed gain",
    "compare": "compare trained runs and baselines on held-out leaders (Table 4, Figs 6, 9, 11, 12)",
    "hcfs": "the HCFS hybrid DDPG/CACC strategy: verify its jerk theorem in closed loop",
    "identify": "identify and certify the car-following law of recorded vehicles (OpenACC, CSV, NGSIM)",
    "platoon": "certify recorded strings head to tail; design the CAV that makes them string stable",
    "demo": "run a demo of the whole pipeline on bundled data",
    "sumo": "run certified and learned controllers inside Eclipse SUMO (check, run, cacc)",
    "sweep": "run a study (a TOML sweep spec) as Dask tasks; resumable, one record per point",
}


class _Parser(argparse.ArgumentParser):
    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        from ._common import NEGATIVE_NUMBER

        self._negative_number_matcher = NEGATIVE_NUMBER  # "-0.5,1,1" is a value

    def error(self, message: str) -> None:  # type: ignore[override]
        """One line on stderr, exit 2: what was wrong, where the options are listed."""
        import re

        message = re.sub(r"invalid (int|float) value: (.*)$",  # argparse's type errors, as
                         lambda m: ("expected an integer" if m[1] == "int" else "expected a number")
                         + f"; got {m[2]}", message)
        self.exit(2, f"{self.prog}: error: {message} (options: {self.prog} --help)\n")


def _chosen(argv: Sequence[str]) -> str | None:
    """The sub-command named in ``argv`` (the first argument not starting with '-')."""
    for a in argv:
        if not a.startswith("-"):
            return a if a in COMMANDS else None
        if a == "--":
            return None
    return None


def build_parser(command: str | None = None, *, lazy: bool = False) -> argparse.ArgumentParser:
    """The argument parser with every sub-command registered.

    With ``lazy``, only ``command`` (if any) is imported and fully registered; the others are
    listed with their :data:`HELP` line, which is all ``stringstab --help`` and argparse's
    choice check need.

    Parameters
    ----------
    command : str, optional
        The sub-command on the command line (None: not known or not given).
    lazy : bool, default False
        Import and register only ``command``; list the others by their help line.

    Returns
    -------
    argparse.ArgumentParser
        The ``stringstab`` parser; each sub-command's parser sets ``func`` to its ``run``.
    """
    parser = _Parser(
        prog="stringstab",
        description="Exact, delay-aware string-stability analysis of car-following controllers.",
    )
    parser.add_argument("--version", action="version", version=f"stringstab {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for name in COMMANDS:
        if lazy and name != command and name in HELP:
            sub.add_parser(name, help=HELP[name], add_help=False)
            continue
        try:
            mod = importlib.import_module(f"{__name__}.{name}")
        except ModuleNotFoundError as e:
            if e.name == f"{__name__}.{name}":
                continue  # command not built yet
            raise
        mod.add_parser(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``stringstab`` console script; returns the exit code.

    Parameters
    ----------
    argv : sequence of str, optional
        The arguments after the program name; default ``sys.argv[1:]``.

    Returns
    -------
    int
        The sub-command's exit code (0 when it returns None); 2 after a
        :class:`~stringstab.errors.StringStabError` or running out of memory (one line on
        stderr); 130 when interrupted (Ctrl-C or SIGTERM); 0 when the output pipe closes early. argparse itself
        exits with 2 on a malformed command line.
    """
    argv = list(sys.argv[1:] if argv is None else argv)
    for stream in (sys.stdout, sys.stderr):  # a file name of undecodable bytes prints, escaped
        try:
            stream.reconfigure(errors="backslashreplace")  # type: ignore[union-attr]
        except (AttributeError, ValueError, OSError):
            pass
    command = _chosen(argv)
    parser = build_parser(command, lazy=True)
    args = parser.parse_args(argv)
    from ..io.manifest import invocation
    from ._provenance import provenance

    hook = sys.unraisablehook

    def quiet_interrupt(u: Any) -> None:  # Ctrl-C landing in a finaliser: not a traceback
        if u.exc_type is not KeyboardInterrupt:
            hook(u)

    sys.unraisablehook = quiet_interrupt
    # SIGTERM (a batch scheduler's time limit, ``kill``) stops a command as Ctrl-C does: one
    # line, outputs complete or absent, a resumable training run; only where nobody else
    # (an embedding program) handles it, and only in the main thread, where Python runs handlers
    term = None
    if (threading.current_thread() is threading.main_thread()
            and signal.getsignal(signal.SIGTERM) is signal.SIG_DFL):
        term = signal.signal(signal.SIGTERM, _terminate)
    try:
        with invocation(lambda: provenance(args, argv)):
            return int(args.func(args) or 0)
    except StringStabError as e:
        msg = str(e).replace("\n", " ")
        print(f"stringstab {args.command}: error: {msg}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        # output folders (OutputDir) and single files (atomic writes) are complete or absent;
        # an interrupted training run stops at a step boundary itself and says how to resume
        print(f"stringstab {args.command}: interrupted; nothing partial was written "
              "(outputs are complete or absent)", file=sys.stderr)
        return 130
    except MemoryError as e:
        detail = f" ({e})" if str(e) else ""
        print(f"stringstab {args.command}: error: out of memory{detail}; expected a smaller "
              "request (fewer grid points, followers or rows)", file=sys.stderr)
        return 2
    except BrokenPipeError:  # pragma: no cover - e.g. piped into head
        return 0
    finally:
        sys.unraisablehook = hook
        if term is not None:
            signal.signal(signal.SIGTERM, term)


def _terminate(signum: int, frame: Any) -> None:
    """SIGTERM as Ctrl-C: raise KeyboardInterrupt where the command is (see :func:`main`)."""
    raise KeyboardInterrupt


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
