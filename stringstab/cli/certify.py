"""``stringstab certify``: exact, delay-aware string-stability certificates for gain triples.

Reads triples from the command line or a file (:func:`stringstab.io.read_gains`),
certifies them on the :class:`~stringstab.certify.api.Loop` they ask for — the continuous-time loop,
the sampled-data loop (``--sample-time``), the multi-rate loop whose V2V messages arrive every
``--message-period`` (with ``--sample-time``), or every member of a box of parameters
(``--tau``, ``--delta``, ``--headway`` as ``LO:HI``) — and writes the batch's columns
(``columns()``; the table's, ``table_columns()``) as a table, JSON, CSV, Parquet or
NPZ (:func:`stringstab.io.write_results`).  ``--max-message-period [CAP]`` writes instead the
largest message period certified with every shorter one
(:func:`stringstab.certify.message_period.largest_message_period`).  Exit code 0
when every triple is certified (with ``--max-message-period``: up to the cap), 1 when any is
not (``not_certified`` or ``inconclusive``), 2 on bad input (nothing printed, no file written).
"""

from __future__ import annotations

import argparse
import sys
import warnings
from typing import Any

from ..errors import StringStabError, show
from ..params import DEFAULT_DELTA, DEFAULT_HEADWAY, DEFAULT_TAU, Box
from ._common import (
    add_gain_arguments,
    add_model_arguments,
    add_output_arguments,
    check_horizon,
    check_output,
    gains_from_args,
    loop_params,
    shown_params,
)
from ._message import add_message_arguments, message_from_args

__all__ = ["DEFAULT_CAP", "PROGRESS_ROWS", "add_parser", "run"]

#: The default cap of ``--max-message-period`` (s); the library's
#: :data:`stringstab.certify.message_period.DEFAULT_CAP` (not imported: the CLI starts light).
DEFAULT_CAP = 0.5

#: Show a progress bar when there are more rows than this (or stderr is a terminal).
PROGRESS_ROWS = 10_000
#: Peak memory per certified row, and the fixed part (measured with ``certify --file`` of
#: 2·10⁴ and 2·10⁵ random triples, NPZ out: peak RSS 121 and 842 MB, ~4.0 kB per row).
BYTES_PER_ROW = 4500
BYTES_BASE = 150e6


def _available() -> float:
    from ..memory import available_bytes

    return float(available_bytes())

_EPILOG = f"""\
examples:
  stringstab certify 0.9,-0.5,1.1 1.3,0,0.6
  stringstab certify -0.5,1,1 --delta 0.3              # negative gains need no quoting
  stringstab certify --file rollout.csv --format json --out certificates.json
  stringstab certify --file big.npz --format parquet --out certificates.parquet
  stringstab certify 0.9,-0.5,1.1 --method pade         # also python-control's Padé numbers
  stringstab certify 1.2,0.5,0.6 --sample-time 0.1       # the loop sampled every 0.1 s (ZOH)
  stringstab certify 1.2,0.5,0.6 --tau 0.1:0.5 --delta 0.1:0.3   # every τ, δ in the box
  stringstab certify 1.2,0.5,0.6 --sample-time 0.01 --message-period 0.1   # 10 Hz V2V, held
  stringstab certify 1.2,0.5,0.6 --sample-time 0.01 --max-message-period 0.5
  stringstab certify 1.2,0.5,0.6 --reaction-delay 0.2   # the command applied 0.2 s late

input files: CSV with a header k_x,k_v,k_a (a gain time series adds t and
optionally vehicle), JSON (a list of {{"k_x","k_v","k_a"}} objects or of triples,
bare or under "gains"), NPZ (arrays k_x, k_v, k_a [, t, vehicle] or K (n,3)) or
Parquet (columns k_x, k_v, k_a [, t, vehicle]).

output: table (for people: sup|Γ| and margin rounded, ω_peak in rad/s; sampled:
also θ_peak in rad/sample; a box: the witness member), or every column in json, csv,
parquet or npz (the last two need --out); sample_time and the box are in every format.
multi-rate (--message-period): sup σ(G) is the l2-induced gain of the link u_(i-1) -> u_i
(lifted over one message period; θ_peak in rad per message period), and the fallback (ACC,
k_a = 0) loop is certified beside it; switching between the two modes and random message
loss are not covered by either certificate.

exit status: 0 every triple certified; 1 some triple not_certified or
inconclusive; 2 bad input (no verdicts printed, no file written).
defaults: tau={DEFAULT_TAU} s, delta={DEFAULT_DELTA} s, headway={DEFAULT_HEADWAY} s (IDL paper
Table 2; tau from Zhou et al. 2020). See docs/certify.md.
"""

def add_parser(sub: Any) -> None:
    """Register ``certify``.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The ``stringstab`` sub-command set (:func:`stringstab.cli.build_parser`); the parser
        added sets ``func`` to :func:`run`.
    """
    p = sub.add_parser(
        "certify",
        help="certify gain triples K = [k_x, k_v, k_a] as string stable (exact delay)",
        description=(
            "Certify whether each gain triple K = [k_x, k_v, k_a] is string stable: Γ(s) "
            "(IDL eq 11, derived) is internally stable and sup_ω |Γ(jω)| ≤ 1 with the exact "
            "delay e^{-jδω}. Reports the verdict (certified / not_certified / inconclusive), "
            "sup|Γ|, its frequency, the margin, and the Taylor Proposition 1 (derived and "
            "printed Ψ) for comparison. With --sample-time H: the same for the sampled-data "
            "loop H(z) (zero-order hold, exact lag and delay); with LO:HI intervals: for every "
            "τ, δ, T* in the box, with a witness member when not certified."
        ),
        epilog=_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    add_gain_arguments(p)
    add_model_arguments(p)
    add_message_arguments(p)
    p.add_argument("--fallback-gains", metavar="K_X,K_V",
                   help="with --message-period: the fallback (ACC, k_a = 0) gains certified beside "
                        "the multi-rate loop (default: each triple's own k_x, k_v)")
    p.add_argument("--max-message-period", nargs="?", const=str(DEFAULT_CAP), metavar="CAP",
                   help="with --sample-time: report the largest message period N*H <= CAP s "
                        f"(default {DEFAULT_CAP:g}) such that every N'*H, N' <= N, is certified")
    p.add_argument("--reaction-delay", metavar="SECONDS",
                   help="reaction (actuation) delay θ_r in s, >= 0, on the whole command "
                        "(τ a' = u(t − θ_r) − a), also with --sample-time; or LO:HI for the "
                        "robust certificate over a box (continuous time; default: 0)")
    p.add_argument("--method", choices=("exact", "pade"), default="exact",
                   help="exact: the sound certificate (default); pade: the same, plus "
                        "python-control's Padé + norm('inf') numbers, warning where they disagree")
    p.add_argument("--pade-order", default="5", metavar="N",
                   help="Padé order of the delay for --method pade (default: 5)")
    add_output_arguments(p)
    p.add_argument("--from", dest="from_identify", metavar="IDENTIFY_JSON",
                   help="certify the vehicles fitted by 'stringstab identify' (identify.json), each "
                        "with its own τ, δ, T* (intervals --tau/--delta/--headway LO:HI replace them)")
    p.add_argument("--no-progress", action="store_true",
                   help=f"never show the progress bar (default: shown on a terminal or > {PROGRESS_ROWS} rows)")
    p.set_defaults(func=run)


def _pade_order(text: str) -> int:
    try:
        n = int(text)
    except ValueError as e:
        raise StringStabError(f"--pade-order must be an integer >= 1; got {show(text)}") from e
    if n < 1:
        raise StringStabError(f"--pade-order must be an integer >= 1; got {show(text)}")
    from ..ranges import check_count

    return check_count("order", n, name="--pade-order")


def _warn_disagreements(records: list[dict[str, Any]], order: int) -> None:
    """One warning on stderr listing (up to five) rows where Padé and the exact verdict differ."""
    bad = [(i, r) for i, r in enumerate(records) if r.get("pade") and not r["pade"].get("agrees", True)]
    if not bad:
        return
    print(
        f"stringstab certify: warning: python-control (Padé order {order}) disagrees with the "
        f"exact certificate on {len(bad)} of {len(records)} row(s); the exact verdict is reported",
        file=sys.stderr,
    )
    for i, r in bad[:5]:
        pade = r["pade"]
        print(
            f"  row {i + 1}: K=({r['k_x']:g}, {r['k_v']:g}, {r['k_a']:g}) exact {r['verdict']} "
            f"(sup|Γ| {r['sup_gain'] if r['sup_gain'] is not None else 'inf'}), "
            f"pade {pade['verdict']} (stable {pade['stable']}, norm {pade['hinf']})",
            file=sys.stderr,
        )
    if len(bad) > 5:
        print(f"  ... and {len(bad) - 5} more", file=sys.stderr)


def run(args: argparse.Namespace) -> int:
    """Run ``certify``; returns 0 (all certified), 1 (some not) or raises on bad input.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of ``stringstab certify``.

    Returns
    -------
    int
        Exit code: 0 when every gain triple (or identified follower) is certified, 1
        when some is not; bad input raises :class:`~stringstab.errors.StringStabError`
        (exit 2 from :func:`stringstab.cli.main`) before anything is written.
    """
    model, H = loop_params(args)
    order = _pade_order(args.pade_order)
    N, phase = message_from_args(args, H)
    fallback = _fallback_gains(args, N)
    from ..certify.api import Loop

    # the values are checked (with the flags' names); the library decides the loop's kind and
    # refuses what no certificate answers (--method pade beyond the continuous point loop)
    loop = Loop(model, H, method=args.method, message_steps=N, message_phase=phase,
                fallback=fallback)
    out = check_output(args)
    if args.max_message_period is not None:
        if N is not None:
            raise StringStabError("--max-message-period searches the message period; expected "
                                  f"no --message-period with it, got --message-period {args.message_period}")
        if H is None:
            raise StringStabError("--max-message-period needs the control period: expected "
                                  "--sample-time H with it, got none")
    if getattr(args, "from_identify", None):
        if N is not None or args.max_message_period is not None:
            raise StringStabError("--from certifies each identified vehicle on its own loop; "
                                  "expected no --message-period or --max-message-period with it")
        return _run_identified(args, out, H, Box.of(model).reaction_delay[0])
    table = gains_from_args(args)
    check_horizon(H, table)
    from ..memory import refuse_if_too_big

    n_rows = len(table)
    refuse_if_too_big(f"{args.file or 'the triples'} ({n_rows} rows)",
                      BYTES_BASE + BYTES_PER_ROW * n_rows,
                      f"expected at most about {int(max(_available() - BYTES_BASE, 0) // BYTES_PER_ROW)} "
                      "rows at once on this machine: split the file")

    from ..io import write_results

    n = len(table)
    if args.max_message_period is not None:
        return _run_max_period(args, loop, table, out)
    progress = not args.no_progress and (sys.stderr.isatty() or n > PROGRESS_ROWS)
    with warnings.catch_warnings():
        # Padé disagreements are reported once, below, instead of per row.
        warnings.simplefilter("ignore")
        batch = loop.certify_batch(table.k_x, table.k_v, table.k_a, pade_order=order,
                                   progress=progress)
    if loop.kind == "continuous":
        params: dict[str, Any] = {"tau": model.tau, "delta": model.delta,
                                  "headway": model.headway, "method": args.method}
        if model.reaction_delay:  # θ_r > 0 only (a θ_r = 0 run writes what it always did)
            params = {**dict(list(params.items())[:3]), "reaction_delay": model.reaction_delay,
                      "method": args.method}
    else:
        params = {**shown_params(model, H), "method": args.method}
    if loop.kind == "multirate":
        params.update(message_period=batch.summary()["message_period"], message_phase=phase)
    if args.method == "pade":
        params["pade_order"] = order
    summary = batch.summary()
    write_results({**table.meta_columns(), **batch.columns()}, out, args.format,
                  params=_for_table(params) if args.format == "table" else params,
                  summary=summary, table=batch.table_columns(), what="--out")
    if args.method == "pade":
        _warn_disagreements([{**table.meta(i), **r} for i, r in enumerate(batch.records())], order)
    if out is not None:
        print(
            f"stringstab certify: {summary['certified']} of {summary['n']} certified; "
            f"wrote {args.format} to {out}",
            file=sys.stderr,
        )
    return 0 if summary["certified"] == summary["n"] else 1


def _fallback_gains(args: argparse.Namespace, N: int | None) -> tuple[float, float] | None:
    """``--fallback-gains K_X,K_V``, checked (multi-rate loop only)."""
    text = getattr(args, "fallback_gains", None)
    if text is None:
        return None
    if N is None or N < 2:
        raise StringStabError("--fallback-gains is for the multi-rate loop; expected --message-period "
                              f"of at least two sample times with it, got --fallback-gains {text}")
    parts = str(text).split(",")
    try:
        fx, fv = (float(v) for v in parts)
    except ValueError as e:
        raise StringStabError(f"--fallback-gains must be K_X,K_V (two numbers); got {text!r}") from e
    from ..params import as_gains

    gx, gv, _ = as_gains(fx, fv, 0.0)
    return float(gx), float(gv)


def _run_max_period(args: argparse.Namespace, loop: Any, table: Any, out: Any) -> int:
    """``certify --max-message-period [CAP]``: the largest certified message period per triple."""
    from ..certify.message_period import largest_message_period
    from ..io import write_results

    try:
        cap = float(args.max_message_period)
    except ValueError as e:
        raise StringStabError("--max-message-period must be a number of seconds >= --sample-time; "
                              f"got {args.max_message_period!r}") from e
    if not cap >= loop.sample_time or cap != cap or cap == float("inf"):
        raise StringStabError(f"--max-message-period must be a finite number of seconds >= "
                              f"--sample-time {loop.sample_time:g}; got {args.max_message_period}")
    from ..ranges import check_count

    check_count("message_steps", int(cap / loop.sample_time + 1e-9),
                name=f"--max-message-period {args.max_message_period} / --sample-time {loop.sample_time:g}")
    b = largest_message_period(loop, table.k_x, table.k_v, table.k_a, cap=cap)
    params = {**shown_params(loop.model, loop.sample_time), "max_message_period_cap": b.cap}
    summary = b.summary()
    write_results({**table.meta_columns(), **b.columns()}, out, args.format,
                  params=_for_table(params) if args.format == "table" else params,
                  summary=summary, table=b.table_columns(), what="--out")
    if out is not None:
        print(f"stringstab certify: {summary['certified']} of {summary['n']} certified up to "
              f"{b.cap:g} s; wrote {args.format} to {out}", file=sys.stderr)
    return 0 if summary["certified"] == summary["n"] else 1


def _for_table(params: dict[str, Any]) -> dict[str, Any]:
    """Intervals as the command line writes them (``0.1:0.5``) in the table's header line."""
    return {k: f"{v[0]:g}:{v[1]:g}" if isinstance(v, list) else v for k, v in params.items()}


def _run_identified(args: argparse.Namespace, out: Any, H: float | None, theta: float) -> int:
    """``certify --from identify.json``: each fitted vehicle at its own τ, δ, T* (or the intervals given)."""
    from ..certify.api import Loop
    from ..identify.report import read_identified
    from ..io import TableColumn, columns_from_records, write_results

    if args.triples or args.file:
        raise StringStabError("expected --from or gain triples/--file, not both")
    rows = read_identified(args.from_identify)
    given = {k: str(getattr(args, k)) for k in ("tau", "delta", "headway") if ":" in str(getattr(args, k))}
    records = []
    for r in rows:
        from ..params import parameter_model

        tau, delta, headway = (given.get(k, r[k]) for k in ("tau", "delta", "headway"))
        # each vehicle at its own fitted θ_r (identify --fit-delay) unless --reaction-delay is given
        # (a LO:HI interval of θ_r is passed on as it is: the box certificate, issue 25 item 4)
        given_theta = getattr(args, "reaction_delay", None)
        theta_r: Any = (r["reaction_delay"] if given_theta is None
                        else str(given_theta) if ":" in str(given_theta) else theta)
        loop = Loop(parameter_model(tau, delta, headway, theta_r), H)
        b = loop.certify_batch([r["k_x"]], [r["k_v"]], [r["k_a"]])
        c: dict[str, Any] = b.records()[0]
        rec: dict[str, Any] = {"position": r["position"], "name": r["name"]}
        for k in ("tau", "delta", "headway"):
            rec[k] = given.get(k, f"{r[k]:.6g}")
        if isinstance(theta_r, str) or theta_r:
            rec["reaction_delay"] = theta_r if isinstance(theta_r, str) else f"{theta_r:.6g}"
        for k in ("k_x", "k_v", "k_a", "verdict", "sup_gain", "peak_omega"):
            if k in c:
                rec[k] = c[k]
        records.append(rec)
    table = [TableColumn("pos", "position", "%d"), TableColumn("name", "name", "%s"),
             TableColumn("k_x", "k_x"), TableColumn("k_v", "k_v"), TableColumn("k_a", "k_a"),
             TableColumn("τ[s]", "tau", "%s"), TableColumn("δ[s]", "delta", "%s"),
             TableColumn("T*[s]", "headway", "%s"), TableColumn("sup|Γ|", "sup_gain"),
             TableColumn("ω_peak[rad/s]", "peak_omega", "%.4g"), TableColumn("verdict", "verdict", "%s")]
    if any("reaction_delay" in r for r in records):  # a θ_r = 0 file writes what it always did
        table.insert(8, TableColumn("θ_r[s]", "reaction_delay", "%s"))
        for r in records:
            r.setdefault("reaction_delay", "0")
    from ..certify.verdicts import Verdict

    n_ok = sum(r["verdict"] == Verdict.CERTIFIED for r in records)
    write_results(columns_from_records(records), out, args.format,
                  params={"from": args.from_identify, "sample_time": H},
                  summary={"n": len(records), "certified": n_ok}, table=table, what="--out")
    return 0 if n_ok == len(records) else 1
