"""``stringstab platoon``: head-to-tail verdicts of recorded strings, and the CAV that stops the wave.

* ``platoon certify FILE`` — the head-to-tail certificate of a string read from an
  ``identify.json`` or a CSV list (:func:`stringstab.mixed.read_vehicles`,
  :func:`stringstab.certify.api.certify_string`), each vehicle's own verdict, the worst
  sub-string and, for an identify.json, the data's own head-to-tail amplification
  (:func:`stringstab.mixed.empirical.string_empirical`).  Exit 0 when the string is certified
  head to tail, 1 when not (``not_certified`` or ``inconclusive``), 2 on bad input.
* ``platoon design --from FILE --cav-at P[,Q]|auto`` — CAV gains that certify the whole string
  (:mod:`stringstab.mixed.design`).  Exit 0 when a design is certified, 1 when none is found.
* ``platoon simulate --from FILE --cav-at ...`` — the recorded leader replayed through the
  string with and without the CAV(s) (:mod:`stringstab.mixed.replay`): m_p along the string,
  figures and a report.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from typing import Any

from ..errors import StringStabError

__all__ = ["add_parser", "run", "run_certify"]

_EPILOG = """\
examples:
  stringstab identify --example acc --out runs/acc
  stringstab platoon certify runs/acc/identify.json
  stringstab platoon certify runs/acc/identify.json --format json
  stringstab platoon certify string.csv --sample-time 0.1

FILE: an identify.json written by 'stringstab identify' (the vehicles in recorded order; its
log is read for the data's own amplification) or a CSV with one row per follower in order and
the columns k_x,k_v,k_a,tau,delta,headway (optional reaction_delay, name, standstill).

See docs/platoon.md.
"""


def add_parser(sub: Any) -> None:
    """Register ``platoon`` (with its sub-commands ``certify``, ``design`` and ``simulate``).

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The ``stringstab`` sub-command set (:func:`stringstab.cli.build_parser`); the parser
        added sets ``func`` to :func:`run`.
    """
    p = sub.add_parser(
        "platoon",
        help="certify recorded strings head to tail; design the CAV that makes them string stable",
        description="Heterogeneous strings of followers (identified cars, CAVs): the sound "
                    "head-to-tail certificate sup_ω ∏|Γ_i(jω)| ≤ 1 with every vehicle internally "
                    "stable, CAV design, and replays of the recorded leader.",
        epilog=_EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    ps = p.add_subparsers(dest="platoon_command", metavar="SUBCOMMAND")
    ps.required = True
    c = ps.add_parser(
        "certify",
        help="the head-to-tail certificate of a string (identify.json or a CSV list)",
        description=(
            "Certify a string of followers head to tail: every vehicle internally stable and "
            "sup_ω ∏_i |Γ_i(jω)| ≤ 1 with the exact delays (a sound branch and bound on the "
            "product, not a grid); each vehicle's own verdict; the worst sub-string (the "
            "longest run of consecutive vehicles proven to amplify); and, for an identify.json, "
            "the data's own amplification from the first car's speed to the last car's.  Exit 0 "
            "when certified head to tail, 1 when not, 2 on bad input."),
        epilog=_EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    _add_input_arguments(c, flag=False)
    c.add_argument("--no-substrings", action="store_true",
                   help="skip the sub-strings (no worst sub-string; faster for long strings)")
    c.add_argument("--no-empirical", action="store_true",
                   help="identify.json: skip the data's own amplification (do not read the log)")
    c.add_argument("--format", choices=("table", "json"), default="table",
                   help="table (default) or json ({\"head_to_tail\": ..., \"vehicles\": [...]})")
    c.set_defaults(func=run)


def _add_input_arguments(p: argparse.ArgumentParser, *, flag: bool) -> None:
    if flag:
        p.add_argument("--from", dest="file", required=True, metavar="FILE",
                       help="identify.json or a CSV list of followers (see certify)")
    else:
        p.add_argument("file", metavar="FILE", help="identify.json or a CSV list of followers")
    p.add_argument("--platoon", metavar="N",
                   help="identify.json of several logs: which platoon (its index)")
    p.add_argument("--sample-time", metavar="H",
                   help="certify the sampled-data loop (every vehicle samples with period H s)")
    p.add_argument("--leader-tau", metavar="S",
                   help="sampled loop: the leader's actuator lag, s (default: the first follower's)")


def run(args: argparse.Namespace) -> int:
    """Run the chosen ``platoon`` sub-command.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line.

    Returns
    -------
    int
        The sub-command's exit code.
    """
    return {"certify": run_certify}[args.platoon_command](args)


def _platoon(args: argparse.Namespace) -> int | None:
    if args.platoon is None:
        return None
    from ._common import integer

    return integer("--platoon", args.platoon, 0)


def _loop_args(args: argparse.Namespace) -> tuple[float | None, float | None]:
    from ..params import positive

    H = None if args.sample_time is None else positive("--sample-time", args.sample_time, unit=" s")
    if args.leader_tau is not None and H is None:
        raise StringStabError("--leader-tau is for the sampled loop; give --sample-time too")
    lt = None if args.leader_tau is None else positive("--leader-tau", args.leader_tau, unit=" s")
    return H, lt


def run_certify(args: argparse.Namespace) -> int:
    """``platoon certify``: the verdicts of a string (module docstring).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line.

    Returns
    -------
    int
        0 certified head to tail, 1 not; bad input raises (exit 2).
    """
    from ..certify.api import certify_string
    from ..mixed import read_vehicles

    H, lt = _loop_args(args)
    rec = read_vehicles(args.file, platoon=_platoon(args))
    emp = None
    emp_note = None
    if rec.kind == "identify" and not args.no_empirical:
        from ..mixed.empirical import string_empirical

        try:
            emp = string_empirical(rec)
        except StringStabError as e:  # the verdict stands without the data's own number
            emp_note = str(e)
    cert = certify_string(rec.vehicles, sample_time=H, leader_tau=lt,
                          substrings=not args.no_substrings)
    doc = cert.as_dict()
    doc["source"] = rec.source
    if rec.kind == "identify":
        doc["head_to_tail"]["empirical"] = None if emp is None else emp.as_dict()
        if emp_note:
            doc["head_to_tail"]["empirical_note"] = emp_note
    if args.format == "json":
        json.dump(doc, sys.stdout, indent=2, allow_nan=False)
        sys.stdout.write("\n")
    else:
        sys.stdout.write(render_certify(doc))
    return 0 if cert.certified else 1


def _g(x: Any, fmt: str = ".4g") -> str:
    return "-" if x is None or (isinstance(x, float) and not math.isfinite(x)) else format(x, fmt)


def render_certify(doc: dict[str, Any]) -> str:
    """The human text of ``platoon certify``: the head-to-tail lines, then one row per vehicle.

    Parameters
    ----------
    doc : dict
        The JSON document of ``platoon certify`` (``head_to_tail``, ``vehicles``).

    Returns
    -------
    str
        Newline-terminated text.
    """
    from ..io import TableColumn, columns_from_records, format_results

    h = doc["head_to_tail"]
    lines = [f"# head to tail ({h['n_vehicles']} vehicles): {h['verdict']} - {h['reason']}",
             f"# sup prod|Γ_i| = {_g(h['sup_gain'], '.6g')} at ω = {_g(h['peak_omega'])} rad/s"
             + (f"; witness ω = {_g(h['witness_omega'])} rad/s" if h.get("witness_omega") is not None else "")]
    w = h.get("worst_substring")
    if w is not None:
        lines.append(f"# worst sub-string: vehicles {w['first']}-{w['last']} ({w['length']}), "
                     f"{w['verdict']}, sup prod|Γ_i| = {_g(w['sup_gain'])} at ω = {_g(w['peak_omega'])} rad/s")
    elif "worst_substring" in h:
        lines.append("# worst sub-string: none (every run of consecutive vehicles is certified)")
    if "empirical" in h:
        e = h["empirical"]
        if e is None:
            lines.append(f"# the data: no head-to-tail estimate ({h.get('empirical_note', 'skipped')})")
        else:
            lines.append(f"# the data (first car -> last car, {e['seconds']:.0f} s): max |Ĝ| = "
                         f"{_g(e['gain'])} ± {_g(e['gain_error'], '.2g')} at ω = {_g(e['omega'], '.3g')} "
                         f"rad/s (amplifies: {e['amplifies']}); peak-to-peak {_g(e['peak_to_peak'], '.3g')}, "
                         f"energy {_g(e['energy'], '.3g')}")
    table = [TableColumn("pos", "position", "%d"), TableColumn("name", "name", "%s"),
             TableColumn("k_x[1/s²]", "k_x", "%.4g"), TableColumn("k_v[1/s]", "k_v", "%.4g"),
             TableColumn("k_a", "k_a", "%.4g"), TableColumn("τ[s]", "tau", "%.4g"),
             TableColumn("δ[s]", "delta", "%.4g"), TableColumn("T*[s]", "headway", "%.4g"),
             TableColumn("stable", "stable"), TableColumn("verdict", "verdict", "%s"),
             TableColumn("sup|Γ|", "sup_gain", "%.5g", missing="inf"),
             TableColumn("ω_peak[rad/s]", "peak_omega", "%.4g")]
    rows = [{k: r.get(k) for k in ("position", "name", "k_x", "k_v", "k_a", "tau", "delta",
                                    "headway", "stable", "verdict", "sup_gain", "peak_omega")}
            for r in doc["vehicles"]]
    text = format_results(columns_from_records(rows), "table", table=table)
    return "\n".join(lines) + "\n" + text
