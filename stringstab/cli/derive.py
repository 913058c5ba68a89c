"""``stringstab derive``: print the derived Γ(s), Ψ1-Ψ3, Λ, gradients and Hurwitz conditions.

With ``--sample-time H``: the sampled-data loop instead (H(z), the characteristic polynomial
Δ(z) and its Schur conditions; :func:`stringstab.derive.derivation.sampled_derivation`); with
a reaction delay θ_r > 0 too, the sampled link's H(z) and χ_f(z) with θ_r
(:func:`stringstab.derive.sampled_reaction.sampled_reaction_derivation`).

SymPy is imported when the command runs, not when it is registered.  ``--out`` is checked
before anything is derived and written atomically; a bad path is one line and exit code 2.
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

from ..errors import StringStabError
from ..io import atomic_write_text, check_output_file

__all__ = ["add_parser", "run"]

def add_parser(sub: Any) -> None:
    """Register ``derive``.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The ``stringstab`` sub-command set (:func:`stringstab.cli.build_parser`); the parser
        added sets ``func`` to :func:`run`.
    """
    p = sub.add_parser(
        "derive",
        help="derive Γ(s), Ψ1-Ψ3, Λ, gradients and Hurwitz conditions symbolically",
        description=(
            "Derive, from the IDL vehicle model (eqs 3-9), the transfer function Γ(s) "
            "(eq 11), the Taylor coefficients Ψ1-Ψ3 and Λ of |D(jω)|²−|N(jω)|² (eqs 12-15), "
            "their gradients (eqs 25-26) and the Hurwitz conditions of Γ's denominator. "
            "With --sample-time H: the sampled-data loop's H(z) (zero-order hold, exact lag and "
            "delay), its characteristic polynomial Δ(z) and the Schur conditions."
        ),
    )
    p.add_argument("--format", choices=("text", "latex", "json"), default=None,
                   help="text, latex or json (default: the --out file's extension .json/.tex, "
                        "else text)")
    p.add_argument(
        "--errata",
        action="store_true",
        help="compare with the formulas printed in the IDL paper",
    )
    p.add_argument(
        "--substitute",
        metavar="NAME=V,...",
        help="specialise, e.g. tau=0.1,delta=0.2,headway=1.1 (also k_x, k_v, k_a)",
    )
    p.add_argument(
        "--delay-order",
        default="exact",
        metavar="N|exact",
        help="Taylor order of e^{-δs} used for Ψ (default: exact delay; the paper's Ψ1 is 3)",
    )
    p.add_argument("--reaction-delay", metavar="SECONDS",
                   help="derive the loop with a reaction delay θ_r on the whole command (issue 25): "
                        "Γ(s) with its quasi-polynomial denominator, g_θ(ω), Ψ with θ_r and the "
                        "Taylor route's (wrong) Hurwitz tests; with --sample-time the sampled "
                        "link's H(z) and characteristic polynomial with θ_r; the same as "
                        "--substitute reaction_delay=SECONDS")
    p.add_argument("--sample-time", metavar="H",
                   help="derive the sampled-data loop with period H s instead (H(z), Δ(z), Schur "
                        "conditions); --substitute may also set tau_prev")
    p.add_argument("--out", metavar="FILE", help="write to FILE instead of standard output")
    p.set_defaults(func=run)


def _delay_order(text: str) -> int | None:
    if text == "exact":
        return None
    try:
        n = int(text)
    except ValueError as e:
        raise StringStabError(f"--delay-order must be 'exact' or an integer >= 0; got {text!r}") from e
    if n < 0:
        raise StringStabError(f"--delay-order must be 'exact' or an integer >= 0; got {text!r}")
    from ..ranges import check_count

    return check_count("order", n, name="--delay-order")


#: The range (:data:`stringstab.ranges.RANGES`) of each symbol ``--substitute`` may set.
_SUBSTITUTE_KINDS = {"tau": "tau", "tau_prev": "tau", "delta": "delta", "headway": "headway",
                     "reaction_delay": "reaction_delay", "k_x": "gain", "k_v": "gain",
                     "k_a": "gain"}


def _check_substitutions(args: argparse.Namespace) -> None:
    """Each ``--substitute NAME=VALUE`` number within its range (refused beyond, warned beyond sensible).

    The syntax, the names and the signs are checked by the derivation
    (:func:`stringstab.derive.symbolic.parse_substitutions`); a value that is not a number is
    left to it.
    """
    from ..ranges import check_magnitude
    from ._common import warn_beyond_sensible

    for item in (args.substitute or "").split(","):
        name, sep, value = item.partition("=")
        kind = _SUBSTITUTE_KINDS.get(name.strip())
        if not sep or kind is None:
            continue
        try:
            x = float(value)
        except ValueError:
            continue
        check_magnitude(kind, x, name=f"--substitute {name.strip()}")
        warn_beyond_sensible(args, [(kind, x, f"--substitute {name.strip()}")])


def _substituted_reaction_delay(text: str | None) -> float:
    """θ_r of ``--substitute reaction_delay=S`` (or ``--reaction-delay``), 0 when absent.

    Checked by the one check of θ_r (:func:`stringstab.params.check_reaction_delay`): a value
    that is not a finite number ≥ 0 is one line, exit 2.
    """
    from ..params import check_reaction_delay

    theta = 0.0
    for item in (text or "").split(","):
        name, sep, value = item.partition("=")
        if sep and name.strip() == "reaction_delay":
            theta = check_reaction_delay(value.strip(), "--substitute reaction_delay")
    return theta


def _without_reaction_delay(text: str | None) -> str | None:
    """``--substitute`` without ``reaction_delay=0`` (θ_r = 0 is the sampled loop of today)."""
    if not text:
        return text
    return ",".join(x for x in text.split(",") if x.partition("=")[0].strip() != "reaction_delay")


def run(args: argparse.Namespace) -> int:
    """Run ``derive``; ``--out`` is checked before any derivation.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of ``stringstab derive``.

    Returns
    -------
    int
        Exit code: 0 when the derivation was written; bad input raises
        :class:`~stringstab.errors.StringStabError` (exit 2 from
        :func:`stringstab.cli.main`).
    """
    from ..derive.derivation import derivation, sampled_derivation
    from ..params import positive

    delay_order = _delay_order(args.delay_order)
    _check_substitutions(args)
    theta = getattr(args, "reaction_delay", None)
    if theta is not None:  # θ_r (issue 25): checked as certify checks it, then substituted
        from ..params import check_reaction_delay

        theta = check_reaction_delay(theta, "--reaction-delay (reaction delay θ_r)")
        args.substitute = ",".join(x for x in (args.substitute, f"reaction_delay={theta}") if x)
    H = None
    if args.sample_time is not None:
        from ..ranges import check_magnitude
        from ._common import warn_beyond_sensible

        H = check_magnitude("sample_time", positive("--sample-time (sampling period H)",
                                                    args.sample_time, unit=" s"),
                            name="--sample-time")
        warn_beyond_sensible(args, [("sample_time", H, "--sample-time")])
        if args.errata or delay_order is not None:
            raise StringStabError(
                "--errata and --delay-order are about the continuous loop's Ψ (IDL eqs 12-15); "
                f"expected neither with --sample-time; got {'--errata' if args.errata else '--delay-order ' + args.delay_order}")
    from ._common import resolve_format

    args.format = resolve_format(args.format, args.out, ("text", "latex", "json"), default="text")
    out = check_output_file(args.out, what="--out") if args.out else None
    theta_r = _substituted_reaction_delay(args.substitute)
    if H is not None and theta_r:  # θ_r with a sample time (issue 25): its own derivation
        from ..certify.lifting_reaction import check_reaction_sampled
        from ..derive.sampled_reaction import sampled_reaction_derivation

        check_reaction_sampled(theta_r, H)  # the certificate's limit (q ≤ 2000), one line
        d = sampled_reaction_derivation(H, theta_r, args.substitute)
    elif H is not None:
        d = sampled_derivation(H, _without_reaction_delay(args.substitute))
    else:
        d = derivation(delay_order, args.substitute, args.errata)
    text = {"json": d.json, "text": d.text, "latex": d.latex}[args.format]()
    if out is not None:
        atomic_write_text(out, text, what="--out")
        print(f"stringstab derive: wrote {args.format} to {out}", file=sys.stderr)
    else:
        print(text, end="")
    return 0
