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

    d = ps.add_parser(
        "design",
        help="CAV gains at given positions (or the fewest CAVs, auto) that certify the string",
        description=(
            "Replace the recorded followers at --cav-at (string positions, the leader is 0) by "
            "CAVs running the predecessor-following eq-4 law with the CAV's own tau, delta, T* "
            "and gain bounds, and find their gains with the largest attenuation margin (the "
            "tuning's CasADi NLP under the exchange method); the head-to-tail certificate judges "
            "the result.  When no design certifies, it says so — proven for one CAV when the "
            "exclusion proof covers the gain bounds — and gives the smallest sup found.  "
            "--cav-at auto tries every position, then pairs (up to --max-cavs).  Exit 0 when a "
            "design is certified, 1 when none is, 2 on bad input."),
        epilog=_DESIGN_EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    _add_input_arguments(d, flag=True, loop=False)
    _add_cav_arguments(d)
    d.add_argument("--format", choices=("table", "json"), default="table",
                   help="table (default) or json (vehicles, head_to_tail, design)")
    d.set_defaults(func=run)

    m = ps.add_parser(
        "simulate",
        help="replay the recorded leader through the string with and without the designed CAV(s)",
        description=(
            "Design the CAV(s) at --cav-at (as 'platoon design'), then replay the recorded leader "
            "(the string's first car, as logged) through the identified followers and through "
            "the string with the CAV(s), in the toolkit's simulator (or SUMO with --sumo): m_p "
            "along the string, energy and peak-to-peak ratios, figures and a report in --out.  "
            "Needs an identify.json (its log).  Exit 0 when it ran, 2 on bad input."),
        epilog=_DESIGN_EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    _add_input_arguments(m, flag=True, loop=False)
    _add_cav_arguments(m)
    m.add_argument("--cav-gains", metavar="KX,KV,KA",
                   help="use these CAV gains (one CAV) instead of designing them")
    m.add_argument("--sumo", action="store_true",
                   help="replay in Eclipse SUMO (the sumo extra) instead of the toolkit's simulator")
    m.add_argument("--no-figures", action="store_true", help="skip the figures")
    m.add_argument("--out", required=True, metavar="DIR", help="output folder")
    m.set_defaults(func=run)


_DESIGN_EPILOG = """\
examples:
  stringstab platoon design --from runs/acc/identify.json --cav-at 5
  stringstab platoon design --from runs/acc/identify.json --cav-at 5 --cav-headway 3
  stringstab platoon design --from string.csv --cav-at auto --max-cavs 2 --format json

The CAV's defaults: tau 0.1 s, delta 0.2 s, T* 1.1 s (IDL Table 2), gains in [-2, 2] with
k_x >= 0.01 1/s^2 (a CAV must hold its gap). See docs/platoon.md.
"""


def _add_cav_arguments(p: argparse.ArgumentParser) -> None:
    from .. import constants

    p.add_argument("--cav-at", required=True, metavar="P[,Q]|auto",
                   help="string positions (1..N; the leader is 0) of the CAVs, or auto")
    p.add_argument("--cav-tau", default=str(constants.TAU), metavar="S",
                   help=f"the CAV's actuator lag, s (default {constants.TAU:g})")
    p.add_argument("--cav-delta", default=str(constants.DELTA), metavar="S",
                   help=f"the CAV's communication delay, s (default {constants.DELTA:g})")
    p.add_argument("--cav-headway", default=str(constants.HEADWAY), metavar="S",
                   help=f"the CAV's desired time headway T*, s (default {constants.HEADWAY:g})")
    p.add_argument("--cav-reaction-delay", default="0", metavar="S",
                   help="the CAV's reaction delay θ_r, s (default 0)")
    lo, hi = constants.GAIN_BOUNDS
    p.add_argument("--gain-bounds", default=f"{lo:g}:{hi:g}", metavar="LO:HI",
                   help=f"bounds of each CAV gain (default {lo:g}:{hi:g}, IDL Table 2)")
    p.add_argument("--min-kx", default="0.01", metavar="X",
                   help="the least k_x of a CAV, 1/s² (default 0.01: it holds its gap)")
    p.add_argument("--max-cavs", default="2", metavar="N",
                   help="--cav-at auto: the most CAVs tried (default 2)")


def _add_input_arguments(p: argparse.ArgumentParser, *, flag: bool, loop: bool = True) -> None:
    if flag:
        p.add_argument("--from", dest="file", required=True, metavar="FILE",
                       help="identify.json or a CSV list of followers (see certify)")
    else:
        p.add_argument("file", metavar="FILE", help="identify.json or a CSV list of followers")
    p.add_argument("--platoon", metavar="N",
                   help="identify.json of several logs: which platoon (its index)")
    p.add_argument("--positions", metavar="A:B",
                   help="identify.json: the recorded positions A..B of the string (default the "
                        "longest run of consecutive identified followers)")
    if loop:
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
    return {"certify": run_certify, "design": run_design,
            "simulate": run_simulate}[args.platoon_command](args)


def _platoon(args: argparse.Namespace) -> int | None:
    if args.platoon is None:
        return None
    from ._common import integer

    return integer("--platoon", args.platoon, 0)


def _span(args: argparse.Namespace) -> tuple[int, int] | None:
    if args.positions is None:
        return None
    text = str(args.positions)
    parts = text.split(":")
    try:
        a, b = (int(x) for x in parts) if len(parts) == 2 else (int(text), int(text))
    except ValueError as e:
        raise StringStabError(f"--positions must be A:B (recorded positions, integers); got "
                              f"{text!r}") from e
    if a < 1 or b < a:
        raise StringStabError(f"--positions must be A:B with 1 <= A <= B; got {text!r}")
    return a, b


def _cav_spec(args: argparse.Namespace) -> Any:
    from ..mixed.cav import CavSpec
    from ..params import check_params, check_reaction_delay, parse_interval, positive

    tau, delta, headway = check_params(args.cav_tau, args.cav_delta, args.cav_headway)
    theta = check_reaction_delay(args.cav_reaction_delay, "--cav-reaction-delay")
    from ..ranges import check_magnitude

    lo, hi = parse_interval(args.gain_bounds, "--gain-bounds")
    min_kx = positive("--min-kx", args.min_kx, allow_zero=True, unit=" 1/s²")
    for name, v in (("--gain-bounds LO", lo), ("--gain-bounds HI", hi), ("--min-kx", min_kx)):
        check_magnitude("gain", v, name=name)
    if max(lo, min_kx) > hi:
        raise StringStabError(f"--gain-bounds {args.gain_bounds} leaves no k_x >= --min-kx "
                              f"{min_kx:g}")
    return CavSpec(tau=tau, delta=delta, headway=headway, reaction_delay=theta, bounds=(lo, hi),
                   min_kx=min_kx)


def _max_cavs(args: argparse.Namespace) -> int:
    from ._common import integer

    return integer("--max-cavs", args.max_cavs, 1, "followers")


def _cav_positions(text: str, n: int) -> tuple[int, ...] | None:
    """``auto`` (None) or the positions, each checked within 1..n."""
    from ..mixed.cav import check_positions

    if str(text).strip().lower() == "auto":
        return None
    out = []
    for part in str(text).split(","):
        try:
            out.append(int(part))
        except ValueError as e:
            raise StringStabError(f"--cav-at must be positions P[,Q] (integers 1..{n}, the leader "
                                  f"is 0) or auto; got {text!r}") from e
    return check_positions(out, n)


def run_design(args: argparse.Namespace) -> int:
    """``platoon design``: CAV gains that certify the string (module docstring).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line.

    Returns
    -------
    int
        0 when a design is certified head to tail, 1 when none is; bad input raises (exit 2).
    """
    from ..mixed import read_vehicles
    from ..mixed.design import design_auto, design_cavs

    spec = _cav_spec(args)
    max_cavs = _max_cavs(args)
    rec = read_vehicles(args.file, platoon=_platoon(args), positions=_span(args))
    pos = _cav_positions(args.cav_at, len(rec.vehicles))
    d = design_auto(rec.vehicles, spec, max_cavs=max_cavs) if pos is None else \
        design_cavs(rec.vehicles, pos, spec)
    doc = d.as_dict()
    _describe(doc, rec)
    doc["design"]["cav"] = {"tau": spec.tau, "delta": spec.delta, "headway": spec.headway,
                            "reaction_delay": spec.reaction_delay,
                            "gain_bounds": list(spec.bounds), "min_kx": spec.min_kx}
    if args.format == "json":
        json.dump(doc, sys.stdout, indent=2, allow_nan=False)
        sys.stdout.write("\n")
    else:
        sys.stdout.write(render_design(doc))
    return 0 if d.certified else 1


def _gains(text: str) -> tuple[float, float, float]:
    from ..io import parse_triple
    from ..ranges import check_magnitude

    K = parse_triple(str(text), where=f"--cav-gains {text!r}")
    for name, v in zip(("k_x", "k_v", "k_a"), K):
        check_magnitude("gain", v, name=f"--cav-gains {name}")
    return K


def run_simulate(args: argparse.Namespace) -> int:
    """``platoon simulate``: design, replay, figures and report (module docstring).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line.

    Returns
    -------
    int
        0 when it ran; bad input raises (exit 2).
    """
    import time

    import numpy as np

    from ..certify.api import certify_string
    from ..io import OutputDir
    from ..mixed import read_vehicles
    from ..mixed.cav import string_with_cavs
    from ..mixed.design import Design, design_cavs
    from ..mixed.replay import replay
    from ..report import command_line
    from ..report.mixed import platoon_report

    t0 = time.perf_counter()
    spec = _cav_spec(args)
    _max_cavs(args)  # not used by a replay at given positions, but checked like design's
    rec = read_vehicles(args.file, platoon=_platoon(args), positions=_span(args))
    if rec.kind != "identify":
        raise StringStabError("platoon simulate replays the recorded leader: expected the "
                              f"identify.json of a log; got the CSV list {rec.source}")
    pos = _cav_positions(args.cav_at, len(rec.vehicles))
    if pos is None:
        raise StringStabError("platoon simulate needs the CAV positions (--cav-at P[,Q]); find "
                              "them first with 'platoon design --cav-at auto'")
    out = OutputDir(args.out, command="platoon simulate", what="--out")
    recorded = certify_string(rec.vehicles)
    if args.cav_gains is not None:
        if len(pos) != 1:
            raise StringStabError("--cav-gains gives one CAV's gains; got several --cav-at positions")
        given = _gains(args.cav_gains)
        K = spec.clip(given)
        if not np.array_equal(K, np.asarray(given)):  # a given gain is used as given, or refused
            raise StringStabError(
                f"--cav-gains {args.cav_gains}: expected gains within --gain-bounds "
                f"{spec.bounds[0]:g}:{spec.bounds[1]:g} with k_x >= --min-kx {spec.min_kx:g}; got "
                f"k_x, k_v, k_a = {', '.join(f'{v:g}' for v in given)} (widen --gain-bounds to use them)")
        vs = string_with_cavs(rec.vehicles, pos, [K], spec)
        cert = certify_string(vs)
        design = Design(pos, ((float(K[0]), float(K[1]), float(K[2])),), vs, cert, float("nan"),
                        cert.certified, f"the given gains: {cert.verdict}")
    else:
        design = design_cavs(rec.vehicles, pos, spec)
    l0 = list(rec.standstill)
    for p in pos:
        l0[p - 1] = spec.standstill
    label = f"CAV at {','.join(str(p) for p in pos)}"
    rp = replay(rec, [(label, design.vehicles, l0)], simulator="sumo" if args.sumo else "toolkit")
    from ..mixed.replay import probe

    w_probe = recorded.peak_omega if recorded.peak_omega > 0 else 0.2
    pr = probe([("recorded", rec.vehicles, rec.standstill), (label, design.vehicles, l0)],
               w_probe, speed=float(np.mean(np.asarray(rp.runs[0].result.speed)[0])))
    emp = None
    try:
        from ..mixed.empirical import string_empirical

        emp = string_empirical(rec)
    except StringStabError:
        emp = None
    rec_doc, des_doc = recorded.as_dict(), design.as_dict()
    _describe(rec_doc, rec)
    _describe(des_doc, rec)
    doc = {"recorded": rec_doc, "design": des_doc, "replay": rp.as_dict(),
           "probe": pr.as_dict(), "empirical": None if emp is None else emp.as_dict()}
    figures: list[str] = []
    with out:
        out.write_json("platoon.json", doc)
        if not args.no_figures:
            figures = _figures(out, rec, design, rp, emp, label)
        names = list(out.written)
        names += platoon_report(rec, recorded, design, rp, figures, empirical=emp, probe=pr,
                                command=command_line(args), started=t0).write(out)
    for r in rp.runs:
        print(f"{r.label}: energy ratio last/leader {r.band_ratio:.3g} (0 < ω ≤ 1 rad/s), "
              f"{r.energy_ratio:.3g} (all ω); peak-to-peak {r.peak_to_peak:.3g}; min gap "
              f"{r.min_gap:.3g} m; collisions {r.collisions}")
    for lab, m_, p_ in zip(pr.labels, pr.measured, pr.predicted):
        print(f"probe at ω = {pr.omega:.3g} rad/s, {lab}: last/leader acceleration amplitude "
              f"{m_:.4g} simulated, {p_:.4g} from ∏|Γ_i(jω)|")
    print(f"recorded string: {recorded.verdict} (sup {recorded.sup_gain:.4g}); with {label}: "
          f"{design.certificate.verdict} (sup {design.certificate.sup_gain:.4g})")
    print(f"wrote {len(names)} files to {out.root}/ (platoon.json, figures, report.md, report.html)")
    return 0


def _figures(out: Any, rec: Any, design: Any, rp: Any, emp: Any, label: str) -> list[str]:
    import matplotlib.pyplot as plt

    from ..plots.mixed import plot_head_to_tail, plot_replay_energy, plot_replay_speeds

    made = []
    r = plot_head_to_tail([("recorded", rec.vehicles), (label, design.vehicles)], empirical=emp)
    r.figure.savefig(out.path("head_to_tail.png"), dpi=110)
    plt.close(r.figure)
    made.append("head_to_tail.png|∏|Γ_i(jω)| of the recorded string and of the string with the "
                "CAV(s), with the data's own first-to-last transfer |Ĝ| where coherent: above the "
                "dashed line 1 a wave grows from the head to the tail.")
    r = plot_replay_speeds(rp)
    r.figure.savefig(out.path("replay_speeds.png"), dpi=110)
    plt.close(r.figure)
    made.append("replay_speeds.png|The recorded leader's speed and the last car's in each replay.")
    r = plot_replay_energy(rp)
    r.figure.savefig(out.path("replay_energy.png"), dpi=110)
    plt.close(r.figure)
    made.append("replay_energy.png|The acceleration energy of each follower over the leader's "
                "(0 < ω ≤ 1 rad/s) along the string, in each replay: above 1 the wave has grown.")
    return made


def render_design(doc: dict[str, Any]) -> str:
    """The human text of ``platoon design``: the design's lines, then the certificate's text.

    Parameters
    ----------
    doc : dict
        The JSON document of ``platoon design``.

    Returns
    -------
    str
        Newline-terminated text.
    """
    ds = doc["design"]
    cav = ds["cav"]
    lines = [f"# CAV: τ = {cav['tau']:g} s, δ = {cav['delta']:g} s, T* = {cav['headway']:g} s, "
             + (f"θ_r = {cav['reaction_delay']:g} s, " if cav.get("reaction_delay") else "") +
             f"gains in [{cav['gain_bounds'][0]:g}, {cav['gain_bounds'][1]:g}], k_x >= {cav['min_kx']:g}",
             f"# design at position(s) {','.join(str(p) for p in ds['cav_positions'])}: "
             + ("certified" if ds["certified"] else "NOT certified") + f" - {ds['note']}"]
    for p, g in zip(ds["cav_positions"], ds["gains"]):
        lines.append(f"#   CAV at {p}: k_x = {g['k_x']:.5g}, k_v = {g['k_v']:.5g}, k_a = {g['k_a']:.5g}")
    for t in ds["tried"]:
        lines.append(f"#   tried {','.join(str(p) for p in t['positions'])}: {t['verdict']}, "
                     f"sup {_g(t['sup_gain'])}, margin {_g(t['margin'])}"
                     + (" (none exists: proven)" if t.get("proven_none") else ""))
    return "\n".join(lines) + "\n" + render_certify(doc)


def _loop_args(args: argparse.Namespace) -> tuple[float | None, float | None]:
    from ..params import positive

    H = None if args.sample_time is None else positive("--sample-time", args.sample_time, unit=" s")
    if args.leader_tau is not None and H is None:
        raise StringStabError("--leader-tau is for the sampled loop; give --sample-time too")
    lt = None if args.leader_tau is None else positive("--leader-tau", args.leader_tau, unit=" s")
    from ..ranges import check_magnitude

    if H is not None:
        check_magnitude("sample_time", H, name="--sample-time")
    if lt is not None:
        check_magnitude("tau", lt, name="--leader-tau")
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
    rec = read_vehicles(args.file, platoon=_platoon(args), positions=_span(args))
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
    _describe(doc, rec)
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


def _describe(doc: dict[str, Any], rec: Any) -> None:
    """The ``string`` object (where the vehicles come from) and each row's recorded position."""
    doc["string"] = {"source": rec.source, "kind": rec.kind, "leader": rec.leader or None,
                     "recorded_positions": list(rec.positions), "log": rec.log,
                     "note": rec.note or None}
    for row, p in zip(doc["vehicles"], rec.positions):
        row["recorded_position"] = p


def _string_lines(doc: dict[str, Any]) -> list[str]:
    s = doc.get("string", {})
    if s.get("kind") != "identify":
        return []
    pos = s["recorded_positions"]
    lines = [f"# string: recorded followers {pos[0]}..{pos[-1]} of {s['source']} behind "
             f"{s.get('leader') or 'the leader'} (string positions 1..{len(pos)})"]
    if s.get("note"):
        lines.append(f"# note: {s['note']}")
    return lines


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
    lines = [*_string_lines(doc), f"# head to tail ({h['n_vehicles']} vehicles): {h['verdict']} - {h['reason']}",
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
             *([TableColumn("θ_r[s]", "reaction_delay", "%.4g", missing="0")]
               if any(r.get("reaction_delay") for r in doc["vehicles"]) else []),
             TableColumn("stable", "stable"), TableColumn("verdict", "verdict", "%s"),
             TableColumn("sup|Γ|", "sup_gain", "%.5g", missing="inf"),
             TableColumn("ω_peak[rad/s]", "peak_omega", "%.4g")]
    rows = [{k: r.get(k) for k in ("position", "name", "k_x", "k_v", "k_a", "tau", "delta",
                                    "headway", "reaction_delay", "stable", "verdict", "sup_gain",
                                    "peak_omega")}
            for r in doc["vehicles"]]
    text = format_results(columns_from_records(rows), "table", table=table)
    return "\n".join(lines) + "\n" + text
