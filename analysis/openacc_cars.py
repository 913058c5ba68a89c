"""The car-level table of every car in the OpenACC logs shipped with stringstab (issue 28).

Runs :func:`stringstab.identify.cars.identify_cars` on both shipped logs
(``stringstab/data/openacc/``: the ACC platoon at the short setting and the human platoon) with
the command's defaults (50 multi-start bootstrap refits, 20-s blocks, 4 starts, seed 0), the
baselines (IDM, OVRV) and, with ``--fit-delay``, the reaction delay θ_r; and, as a check of the
pooling, fits each car once on its whole log and once on the log cut in two halves and pooled
(no bootstrap): the two estimates differ only by the restart at the cut.

Writes ``analysis/openacc_cars.md`` (the table, the notes that matter for each car, the split
check, the command, the time taken and the machine's load) and, with ``--outputs DIR``, the
command's own files of the same run there (``cars.json``, ``cars.csv``, figures, report), from
which docs/identify.md's figures are copied.  Example::

    python analysis/openacc_cars.py --fit-delay --outputs runs/openacc_cars
"""

from __future__ import annotations

import argparse
import math
import os
import time
from pathlib import Path

from stringstab.identify import PlatoonLog, example_log, fit_follower, read_logs
from stringstab.identify.cars import identify_cars, pool_records
from stringstab.identify.estimate import certify_fit
from stringstab.identify.record import follower_record


def _f(x: float, fmt: str = ".3g") -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "-"
    return "0" if abs(x) < 1e-6 else format(x, fmt)


def _iv(lo: float, hi: float) -> str:
    return f"{_f(lo)}-{_f(hi)}"


def _half(lg: PlatoonLog, sl: slice) -> PlatoonLog:
    return PlatoonLog(lg.t[sl], lg.positions, lg.names, lg.speed[:, sl], {k: g[sl] for k, g in lg.gap.items()},
                      None, lg.source, lg.fmt, lg.meta)


def main() -> None:
    """Run the table and the split check; write the markdown."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bootstrap", type=int, default=50)
    ap.add_argument("--fit-delay", action="store_true")
    ap.add_argument("--no-baselines", action="store_true")
    ap.add_argument("--out", default=str(Path(__file__).with_name("openacc_cars.md")))
    ap.add_argument("--outputs", metavar="DIR", help="also write the command's files of this run here")
    a = ap.parse_args()
    load0 = os.getloadavg()
    t0 = time.perf_counter()
    c0 = time.process_time()
    logs = [lg for name in ("acc", "human") for lg in read_logs(example_log(name))]
    res = identify_cars(logs, bootstrap=a.bootstrap, fit_delay=a.fit_delay, baselines=not a.no_baselines,
                        progress=True)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    load1 = os.getloadavg()
    if a.outputs:
        from stringstab.identify.report import write_cars_outputs
        from stringstab.io import OutputDir
        from stringstab.report.commands import cars_report

        with OutputDir(a.outputs, command="identify", what="--outputs") as out:
            names = list(write_cars_outputs(res, out))
            cars_report(res, names, command="python analysis/openacc_cars.py", started=t0).write(out)
    lines = ["# OpenACC cars: one row per car and setting (generated)", "",
             f"`python analysis/openacc_cars.py{' --fit-delay' if a.fit_delay else ''}"
             f"{'' if a.bootstrap == 50 else f' --bootstrap {a.bootstrap}'}"
             f"{' --no-baselines' if a.no_baselines else ''}` — equivalently "
             "`stringstab identify stringstab/data/openacc/*.csv.gz --by car"
             f"{' --fit-delay' if a.fit_delay else ''}{'' if a.no_baselines else ' --baselines'}"
             f"{'' if a.bootstrap == 50 else f' --bootstrap {a.bootstrap}'} --out DIR`.",
             f"Logs: {', '.join(Path(s).name for s in res.sources)}; {a.bootstrap} bootstrap refits (each "
             "from the point estimate and a random start), 20-s blocks, 4 starts, seed 0; "
             f"{wall / 60:.1f} min wall, {cpu / 60:.1f} min CPU, machine load {load0[0]:.1f} before, "
             f"{load1[0]:.1f} after.", "",
             "Columns: the jointly fitted law (k_a = 0), T* with its 5-95 % bootstrap interval and the "
             "log's median time gap (= T* + l_0/v), sup|Γ| with its interval, the verdict the bootstrap "
             "supports (certified / not certified only when every refit agrees) with the share of refits "
             "certified, the data's own max |Ĝ| ± 2ε below 1 rad/s, and the baselines' speed RMSE and "
             "the verdict of their linearisation (IDM at the median speed, OVRV exact), beside the law's "
             "RMSE from the measured initial state (the baselines' footing).", "",
             "| car | setting | logs | k_x [1/s²] | k_v [1/s] | τ [s] | θ_r [s] | T* [s] (5-95 %) | median time gap [s] "
             "| l_0 [m] | sup\\|Γ\\| (5-95 %) | verdict | certified share | data: max\\|Ĝ\\| ± 2ε | law RMSE v "
             "(measured start) | IDM RMSE v, verdict | OVRV RMSE v, verdict |",
             "|" + "---|" * 17]
    for c in res.cars:
        r = c.row()
        f = c.fields()
        lo, hi = r["headway_interval"]
        slo, shi = r["sup_gain_interval"]
        idm = (f"{_f(f.get('idm_rmse_speed', math.nan))}, {f.get('idm_verdict', '-')}"
               if "idm_verdict" in f else "-")
        ovrv = (f"{_f(f.get('ovrv_rmse_speed', math.nan))}, {f.get('ovrv_verdict', '-')}"
                if "ovrv_verdict" in f else "-")
        lines.append(
            f"| {c.car} | {c.setting} | {len(c.logs)} | {_f(r['k_x'])} | {_f(r['k_v'])} | {_f(r['tau'])} | "
            f"{_f(r['reaction_delay'])} | {_f(r['headway'])} ({_iv(lo, hi)}) | {_f(f['median_time_gap'])} | "
            f"{_f(r['standstill'])} | {r['sup_gain']:.3f} ({_iv(slo, shi)}) | {r['verdict']} | "
            f"{100 * r['certified_share']:.0f} % | {_f(f['empirical_gain'])} ± {_f(f['empirical_gain_error'], '.2g')} "
            f"({f['data_amplifies']}) | {_f(f['rmse_speed_measured_start'])} | {idm} | {ovrv} |")
    lines += ["", "## Notes per car", ""]
    keep = ("spacing policy", "profile over", "the profile over", "T* constrained", "not following", "bridged",
            "model-only", "poor fit", "model and data", "the data alone", "in ", "stopped at the bound",
            "θ_r held at", "the fitted model's simulated")
    for c in res.cars:
        lines.append(f"**{c.car} ({c.setting})**: {c.statement()}")
        lines += [f"- {n}" for n in c.fit.notes + c.notes if n.startswith(keep)]
        lines.append("")
    lines += ["## The pooling checked: each log cut in two halves and pooled, against the whole log", "",
              "No bootstrap; 4 starts; the halves differ from the whole only by the restart at the cut.", "",
              "| log | car | k_x whole / halves | k_v | τ | θ_r | T* | sup\\|Γ\\| | verdict |", "|" + "---|" * 9]
    for lg in logs:
        h = lg.t.size // 2
        for p in lg.followers():
            whole = follower_record(lg, p)
            parts = [follower_record(_half(lg, sl), p) for sl in (slice(0, h), slice(h, None))]
            if not whole.data.segments or not all(q.data.segments for q in parts):
                continue
            fw = fit_follower(whole.data, fit_delay=a.fit_delay)
            fp = fit_follower(pool_records(parts), fit_delay=a.fit_delay)
            cw, cp = certify_fit(fw.params, None), certify_fit(fp.params, None)
            cells = [f"{_f(fw.params[k])} / {_f(fp.params[k])}"
                     for k in ("k_x", "k_v", "tau", "reaction_delay", "headway")]
            lines.append(f"| {Path(lg.source).name} | {lg.name(p)} | " + " | ".join(cells)
                         + f" | {float(cw.sup_gain):.3f} / {float(cp.sup_gain):.3f} | {cw.verdict} / {cp.verdict} |")
    Path(a.out).write_text("\n".join(lines) + "\n", encoding="utf-8")
    print(f"wrote {a.out} ({wall / 60:.1f} min)")


if __name__ == "__main__":
    main()
