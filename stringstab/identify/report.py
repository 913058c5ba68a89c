"""Outputs of ``stringstab identify``: the table, ``identify.json``, CSV/Parquet, figures.

Files (all written through one :class:`stringstab.io.OutputDir`, all-or-nothing):

* ``identify.json`` — :meth:`IdentifyResult.document`: settings, ``vehicles`` (the per-follower
  fields with ``segments`` and ``notes``), followers ``skipped``;
* ``identify.csv`` and ``identify.parquet`` — the same rows, through
  :func:`stringstab.io.write_results`;
* ``fit_<position>.png`` — measured vs simulated speed and gap of each follower;
* ``transfer_<position>.png`` — the model's |Γ(jω)| beside the empirical |Ĝ(jω)| and coherence;
* ``sup_gain.png`` — sup|Γ| with its bootstrap interval and the empirical amplification along
  the platoon.

With ``--by car`` (:func:`stringstab.identify.cars.identify_cars`): ``cars.json`` (the ``cars``
list), ``cars.csv`` and ``cars.parquet`` (intervals as ``_lo``/``_hi`` columns), per car
``fit_<car>_<setting>.png`` and ``transfer_<car>_<setting>.png``, and ``cars.png`` (sup|Γ| per
car with its interval beside the data's own amplification): :func:`write_cars_outputs`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from ..certify.verdicts import Verdict
from ..io import OutputDir, TableColumn, columns_from_records, format_results, write_results
from .core import IdentifyResult
from .estimate import simulated

__all__ = ["CARS_TABLE", "TABLE", "car_tag", "render", "render_cars", "write_cars_outputs", "write_outputs"]

#: The human table.
TABLE = [
    TableColumn("pos", "position", "%d"),
    TableColumn("name", "name", "%s"),
    TableColumn("k_x[1/s²]", "k_x", "%.3g"),
    TableColumn("k_v[1/s]", "k_v", "%.3g"),
    TableColumn("k_a", "k_a", "%.3g"),
    TableColumn("τ[s]", "tau", "%.3g"),
    TableColumn("T*[s]", "headway", "%.3g"),
    TableColumn("l0[m]", "standstill", "%.3g"),
    TableColumn("θ_r[s]", "reaction_delay", "%.3g"),
    TableColumn("rmse_v[m/s]", "rmse_speed", "%.3g"),
    TableColumn("rmse_gap[m]", "rmse_gap", "%.3g"),
    TableColumn("sup|Γ|", "sup_gain", "%.4g"),
    TableColumn("sup|Γ| 5-95%", "sup_interval", "%s"),
    TableColumn("ω_peak[rad/s]", "peak_omega", "%.3g"),
    TableColumn("verdict", "verdict", "%s"),
    TableColumn("bootstrap", "supported_verdict", "%s"),
    TableColumn(Verdict.CERTIFIED.value, "certified_share", "%.2f"),
    TableColumn("box", "box_verdict", "%s"),
    TableColumn("|Ĝ|max", "empirical_gain", "%.3g"),
    TableColumn("data>1", "data_amplifies", "%s"),
    TableColumn("p2p", "peak_to_peak", "%.3g"),
    TableColumn("energy", "energy_gain", "%.3g"),
]

#: The car-level table (``--by car``).
CARS_TABLE = [
    TableColumn("car", "car", "%s"),
    TableColumn("setting", "setting", "%s"),
    TableColumn("logs", "n_logs", "%d"),
    TableColumn("k_x[1/s²]", "k_x", "%.3g"),
    TableColumn("k_v[1/s]", "k_v", "%.3g"),
    TableColumn("τ[s]", "tau", "%.3g"),
    TableColumn("θ_r[s]", "reaction_delay", "%.3g"),
    TableColumn("T*[s]", "headway", "%.3g"),
    TableColumn("T* 5-95%", "headway_text", "%s"),
    TableColumn("l0[m]", "standstill", "%.3g"),
    TableColumn("sup|Γ|", "sup_gain", "%.4g"),
    TableColumn("sup|Γ| 5-95%", "sup_text", "%s"),
    TableColumn("verdict", "verdict", "%s"),
    TableColumn(Verdict.CERTIFIED.value, "certified_share", "%.2f"),
    TableColumn("|Ĝ|max", "empirical_gain", "%.3g"),
    TableColumn("data>1", "data_amplifies", "%s"),
]

#: Baseline columns, added to a table when the baselines were fitted.
BASELINE_COLUMNS = [
    TableColumn("IDM rmse_v", "idm_rmse_speed", "%.3g"),
    TableColumn("IDM", "idm_verdict", "%s"),
    TableColumn("OVRV rmse_v", "ovrv_rmse_speed", "%.3g"),
    TableColumn("OVRV", "ovrv_verdict", "%s"),
    TableColumn("law rmse_v (measured start)", "rmse_speed_measured_start", "%.3g"),
]

#: Every file name the command may write (figures are added per follower).
FILES = ("identify.json", "identify.csv", "identify.parquet", "sup_gain.png")


def _interval(lo: float, hi: float) -> str:
    """``lo-hi`` to 3 digits, solver noise within 1e-6 of 0 shown as 0; ``-`` when unknown."""
    def f(x: float) -> str:
        return "0" if abs(x) < 1e-6 else f"{x:.3g}"

    return f"{f(lo)}-{f(hi)}" if math.isfinite(lo) and math.isfinite(hi) else "-"


def _table_rows(res: IdentifyResult) -> list[dict[str, Any]]:
    rows = []
    for r in res.rows():
        lo, hi = r["sup_gain_lo"], r["sup_gain_hi"]
        r["sup_interval"] = f"{lo:.3g}-{hi:.3g}" if math.isfinite(lo) else "-"
        rows.append(r)
    return rows


def render(res: IdentifyResult) -> str:
    """The per-follower table, its settings line, and a statement per follower below it.

    Parameters
    ----------
    res : IdentifyResult
        The identification of one or more platoons.

    Returns
    -------
    str
        The text report (newline-terminated): the table, then per follower its statement and
        notes as ``#`` lines, then the skipped inputs.
    """
    rows = _table_rows(res)
    params = {"model": res.model, "sample_time": res.sample_time or "continuous",
              "bootstrap": res.settings["bootstrap"], "block_s": res.settings["block"]}
    table = TABLE + (BASELINE_COLUMNS if res.settings.get("baselines") else [])
    text = format_results(columns_from_records(rows), "table", params=params, table=table)
    lines = [text.rstrip("\n")]
    for v in res.vehicles:
        lines.append(f"# {v.position} {v.name}: {v.statement()}")
        for n in v.fit.notes + v.notes:
            lines.append(f"#   note: {n}")
    for s in res.skipped:
        lines.append(f"# skipped: {s}")
    return "\n".join(lines) + "\n"


def write_outputs(res: IdentifyResult, out: OutputDir, *, figures: bool = True) -> list[str]:
    """Write the JSON, CSV, Parquet (and figures) into a staged :class:`OutputDir`.

    Parameters
    ----------
    res : IdentifyResult
        The identification to write.
    out : OutputDir
        The staged output folder (the caller commits it).
    figures : bool, default True
        Also write, per follower, the fit and transfer-function figures and the platoon's
        sup-gain figure (PNG).

    Returns
    -------
    list of str
        The names written into ``out`` so far (``out.written``).
    """
    out.write_json("identify.json", res.document())
    cols = columns_from_records(res.rows())
    params = {"model": res.model, "sample_time": res.sample_time}
    write_results(cols, out.path("identify.csv"), "csv", params=params)
    write_results(cols, out.path("identify.parquet"), "parquet", params=params)
    if figures:
        for v in res.vehicles:
            tag = f"{v.platoon}_{v.position}" if len(res.sources) > 1 else f"{v.position}"
            _fig_fit(v).savefig(out.path(f"fit_{tag}.png"), dpi=110)
            _fig_transfer(v, res.sample_time).savefig(out.path(f"transfer_{tag}.png"), dpi=110)
        _fig_platoon(res).savefig(out.path("sup_gain.png"), dpi=110)
    return out.written


def _figure(w: float, h: float) -> Any:
    from matplotlib.figure import Figure

    return Figure(figsize=(w, h), layout="constrained")


def _num(x: float, name: str, at_bound: Sequence[str], unit: str = "") -> str:
    """A fitted value as a reader should see it: 3 significant digits, solver noise as 0.

    A value within 1e-6 of zero (a fit that ran onto the bound T* ≥ 0 returns 8.9e-08) is
    printed ``0``; a parameter at a bound of the fit says so.
    """
    text = ("0" if abs(x) < 1e-6 else f"{x:.3g}") + (f" {unit}" if unit else "")
    return text + (" (at its bound)" if name in at_bound else "")


def _small(x: float, unit: str) -> str:
    """An error as a title shows it: two digits, and "< 0.01" below the resolution of a log."""
    return f"< 0.01 {unit}" if x < 0.01 else f"{x:.2g} {unit}"


def _who(v: Any) -> str:
    """A follower ("follower 2 (BMW_I3)") or a car ("BMW_I3, short setting, 3 logs")."""
    if hasattr(v, "car"):
        return f"{v.car}, {v.setting} setting, {len(v.logs)} log{'s' if len(v.logs) != 1 else ''}"
    return f"follower {v.position} ({v.name})"


def _fig_fit(v: Any) -> Any:
    fig = _figure(9, 5.5)
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    gaps, speeds = simulated(v)
    dt = v.data.dt
    for i, (s, g, sp) in enumerate(zip(v.segments, gaps, speeds)):
        t = np.arange(s.start, s.stop) * dt
        lab = (lambda x: x) if i == 0 else (lambda x: None)
        ax1.plot(t, v.data.v_pred[s.start:s.stop], color="0.6", lw=0.8, label=lab("predecessor (measured)"))
        ax1.plot(t, v.data.v[s.start:s.stop], color="k", lw=1.0, label=lab("follower (measured)"))
        ax1.plot(t, sp, color="#D55E00", lw=1.0, ls="--", label=lab("follower (simulated)"))
        ax2.plot(t, v.data.gap[s.start:s.stop], color="k", lw=1.0, label=lab("measured"))
        ax2.plot(t, g, color="#D55E00", lw=1.0, ls="--", label=lab("simulated"))
    ax1.set_ylabel("speed (m/s)")
    ax2.set_ylabel("gap (m)")
    ax2.set_xlabel("time from the log's start (s)" if not hasattr(v, "car")
                   else "time along the pooled record (the logs end to end, s)")
    ax1.legend(fontsize=8)
    ax2.legend(fontsize=8)
    p = v.fit.params
    b = list(v.fit.at_bound)
    theta = (f", θ_r = {_num(p['reaction_delay'], 'reaction_delay', b, 's')}"
             if "reaction_delay" in v.fit.names else "")
    params = (f"k_x = {_num(p['k_x'], 'k_x', b, '1/s²')}, k_v = {_num(p['k_v'], 'k_v', b, '1/s')}, "
              f"τ = {_num(p['tau'], 'tau', b, 's')}{theta}, T* = {_num(p['headway'], 'headway', b, 's')}, "
              f"l0 = {_num(p['standstill'], 'standstill', b, 'm')}")
    head = f"{_who(v)}, fitted: {params}"
    if len(head) > 110:  # the parameters on a line of their own (θ_r and bounds lengthen it)
        head = f"{_who(v)}, fitted:\n{params}"
    ax1.set_title(f"{head}\nfit error (RMSE): speed {_small(v.fit.rmse_speed, 'm/s')}, gap "
                  f"{_small(v.fit.rmse_gap, 'm')}", fontsize=9)
    return fig


def _fig_transfer(v: Any, H: float | None) -> Any:
    from ..certify.frequency import gain

    fig = _figure(7, 5.8)
    ax1, ax2 = fig.subplots(2, 1, sharex=True, height_ratios=(3, 1))
    e = v.empirical
    p = v.fit.params
    peak_w = float(v.certificate.peak_omega)
    sup = float(v.certificate.sup_gain)
    w_data = float(e.omega[1]) if e.omega.size > 1 else 0.01
    # from a decade below the model's peak (or the data) up: the model's whole shape is shown
    w_lo = min(w_data, peak_w / 10 if math.isfinite(peak_w) and peak_w > 0 else w_data, 0.01)
    w = np.geomspace(w_lo, 10.0, 600)
    if p.get("reaction_delay", 0.0) > 0:
        from ..certify.reaction import gain_squared

        model = np.sqrt(gain_squared(w, p["k_x"], p["k_v"], p["k_a"], tau=p["tau"], delta=p["delta"],
                                     headway=p["headway"], reaction_delay=p["reaction_delay"]))
    else:
        model = gain(w, p["k_x"], p["k_v"], p["k_a"], tau=p["tau"], delta=p["delta"], headway=p["headway"])
    ax1.loglog(w, model, color="#D55E00", label="model |Γ(jω)| (continuous)")
    if math.isfinite(sup) and math.isfinite(peak_w) and peak_w > 0:
        ax1.plot([peak_w], [sup], "D", color="#D55E00", ms=6,
                 label=f"model peak: sup|Γ| = {sup:.3g} at {peak_w:.2g} rad/s")
    m = (e.omega > 0) & (e.omega <= 10.0)
    good = m & (e.coherence >= 0.5)
    mag = np.abs(e.transfer)
    ax1.loglog(e.omega[m], mag[m], color="0.7", lw=0.8, label="empirical |Ĝ| (all)")
    err = (np.asarray(e.error, dtype=float) if e.error is not None
           else np.full(mag.shape, np.nan))
    band = np.where(np.isfinite(err), 2 * err * mag, 0.0)
    lower = np.minimum(band, 0.95 * mag)  # a log axis cannot show a bar reaching 0
    ax1.errorbar(e.omega[good], mag[good], yerr=np.vstack([lower[good], band[good]]), fmt="o",
                 ms=3, color="k", ecolor="0.35", elinewidth=0.8, capsize=1.5,
                 label="empirical |Ĝ| ± 2ε (coherence ≥ 0.5)")
    ax1.axhline(1.0, color="0.3", lw=0.6, ls=":")
    from .empirical import OMEGA_MAX

    for ax in (ax1, ax2):
        ax.axvspan(OMEGA_MAX, 10.0, color="0.92", zorder=0)
        if w_lo < w_data:
            ax.axvspan(w_lo, w_data, color="0.96", zorder=0)
    ax1.text(OMEGA_MAX * 1.1, 0.04, "not used for the data's verdict\n(common-mode GPS error)",
             transform=ax1.get_xaxis_transform(), fontsize=8, color="0.35")
    if w_lo < w_data:
        ax1.text(w_lo * 1.1, 0.04, f"no data below\n{w_data:.2g} rad/s\n(log length)",
                 transform=ax1.get_xaxis_transform(), fontsize=8, color="0.35")
    ax1.set_ylabel("|follower speed / predecessor speed|")
    ax1.legend(fontsize=8, loc="lower center")
    ax1.set_title(f"{_who(v)}: {v.certificate.verdict}"
                  + ("" if H is None else f", certified sampled at H = {H:g} s"), fontsize=9)
    ax2.semilogx(e.omega[m], e.coherence[m], color="k", lw=0.8)
    ax2.axhline(0.5, color="0.3", lw=0.6, ls=":")
    ax2.set_ylim(0, 1.05)
    ax2.set_xlim(w_lo, 10.0)
    ax2.set_ylabel("coherence")
    ax2.set_xlabel("ω (rad/s)")
    return fig


def _fig_platoon(res: IdentifyResult) -> Any:
    import textwrap

    fig = _figure(7, 4.2)
    ax = fig.add_subplot()
    x = np.arange(len(res.vehicles))
    sup = np.array([float(v.certificate.sup_gain) for v in res.vehicles])
    iv = np.array([v.interval("sup_gain") for v in res.vehicles]).reshape(-1, 2)
    lo = np.where(np.isfinite(iv[:, 0]), np.minimum(sup - iv[:, 0], sup - 0), 0.0)
    hi = np.where(np.isfinite(iv[:, 1]), iv[:, 1] - sup, 0.0)
    ax.errorbar(x - 0.08, sup, yerr=np.clip(np.vstack([lo, hi]), 0, None), fmt="o", color="#D55E00",
                capsize=3, label="model sup|Γ| (5-95 % bootstrap)")
    g = np.array([v.empirical.gain for v in res.vehicles], dtype=float)
    ge = np.array([v.empirical.gain_error for v in res.vehicles], dtype=float)
    ax.errorbar(x + 0.08, g, yerr=np.where(np.isfinite(ge), 2 * ge * g, 0.0), fmt="s", color="k",
                capsize=3, label="empirical max |Ĝ| ± 2ε")
    ax.plot(x, [v.empirical.energy for v in res.vehicles], "^", color="0.5", label="energy amplification")
    ax.axhline(1.0, color="0.3", lw=0.6, ls=":")
    ax.set_xticks(x, [f"{v.position}\n" + textwrap.fill(v.name.replace("_", " "), 14)
                      for v in res.vehicles], fontsize=8)
    ax.set_ylabel("amplification (follower over predecessor)")
    ax.set_title("along the platoon: above the dotted line at 1 a follower amplifies", fontsize=9)
    ax.legend(fontsize=8)
    return fig


def car_tag(car: Any) -> str:
    """The file-name tag of a car: ``<car>_<setting>``.

    Characters other than letters, digits, ``-`` and ``_`` are replaced by ``_``.

    Parameters
    ----------
    car : CarResult
        A car of :func:`stringstab.identify.cars.identify_cars`.

    Returns
    -------
    str
        E.g. ``MERCEDES_GLE450_short``.
    """
    import re

    return re.sub(r"[^A-Za-z0-9_-]", "_", f"{car.car}_{car.setting}")


def _cars_rows(res: Any) -> list[dict[str, Any]]:
    rows = []
    for c in res.cars:
        r = c.flat_row()
        r["n_logs"] = len(c.logs)
        r["headway_text"] = _interval(r["headway_interval_lo"], r["headway_interval_hi"])
        r["sup_text"] = _interval(r["sup_gain_interval_lo"], r["sup_gain_interval_hi"])
        rows.append(r)
    return rows


def render_cars(res: Any) -> str:
    """The car-level table, its settings line, and per car its statement and notes.

    Parameters
    ----------
    res : CarsResult
        :func:`stringstab.identify.cars.identify_cars`.

    Returns
    -------
    str
        The text report (newline-terminated).
    """
    params = {"model": res.model, "sample_time": res.sample_time or "continuous",
              "bootstrap": res.settings["bootstrap"], "block_s": res.settings["block"], "by": "car"}
    table = CARS_TABLE + (BASELINE_COLUMNS if res.settings.get("baselines") else [])
    text = format_results(columns_from_records(_cars_rows(res)), "table", params=params, table=table)
    lines = [text.rstrip("\n")]
    for c in res.cars:
        lines.append(f"# {c.car} ({c.setting}): {c.statement()}")
        for n in c.fit.notes + c.notes:
            lines.append(f"#   note: {n}")
    for sk in res.skipped:
        lines.append(f"# skipped: {sk}")
    return "\n".join(lines) + "\n"


def write_cars_outputs(res: Any, out: OutputDir, *, figures: bool = True) -> list[str]:
    """Write ``cars.json``, ``cars.csv``, ``cars.parquet`` (and figures) into a staged folder.

    Parameters
    ----------
    res : CarsResult
        The car-level identification.
    out : OutputDir
        The staged output folder (the caller commits it).
    figures : bool, default True
        Also write per car the fit and transfer figures and ``cars.png``.

    Returns
    -------
    list of str
        The names written into ``out`` so far (``out.written``).
    """
    out.write_json("cars.json", res.document())
    cols = columns_from_records(res.rows())
    params = {"model": res.model, "sample_time": res.sample_time, "by": "car"}
    write_results(cols, out.path("cars.csv"), "csv", params=params)
    write_results(cols, out.path("cars.parquet"), "parquet", params=params)
    if figures:
        for c in res.cars:
            _fig_fit(c).savefig(out.path(f"fit_{car_tag(c)}.png"), dpi=110)
            _fig_transfer(c, res.sample_time).savefig(out.path(f"transfer_{car_tag(c)}.png"), dpi=110)
        _fig_cars(res).savefig(out.path("cars.png"), dpi=110)
    return out.written


def _fig_cars(res: Any) -> Any:
    import textwrap

    n = len(res.cars)
    fig = _figure(max(7.0, 0.85 * n), 4.6)
    ax = fig.add_subplot()
    x = np.arange(n)
    sup = np.array([float(c.certificate.sup_gain) for c in res.cars])
    iv = np.array([c.interval("sup_gain") for c in res.cars]).reshape(-1, 2)
    lo = np.where(np.isfinite(iv[:, 0]), sup - iv[:, 0], 0.0)
    hi = np.where(np.isfinite(iv[:, 1]), iv[:, 1] - sup, 0.0)
    ax.errorbar(x - 0.08, sup, yerr=np.clip(np.vstack([lo, hi]), 0, None), fmt="o", color="#D55E00",
                capsize=3, label="model sup|Γ| (5-95 % bootstrap)")
    g = np.array([c.empirical.gain for c in res.cars], dtype=float)
    ge = np.array([c.empirical.gain_error for c in res.cars], dtype=float)
    ax.errorbar(x + 0.08, g, yerr=np.where(np.isfinite(ge), 2 * ge * g, 0.0), fmt="s", color="k",
                capsize=3, label="data's max |Ĝ| ± 2ε (pooled)")
    ax.axhline(1.0, color="0.3", lw=0.6, ls=":")
    ax.set_xticks(x, [textwrap.fill(c.car.replace("_", " "), 9) + f"\n({c.setting}, {len(c.logs)})"
                      for c in res.cars], fontsize=7)
    ax.set_xlabel("car (setting, logs pooled)", fontsize=8)
    ax.set_ylabel("amplification (follower over predecessor)")
    ax.set_title("one row per car and setting: above the dotted line at 1 a car amplifies", fontsize=9)
    ax.legend(fontsize=8)
    return fig


def read_identified(path: str, *, vehicle: int | None = None) -> list[dict[str, Any]]:
    """The fitted vehicles of an ``identify.json`` (for ``certify --from`` and ``simulate --from``).

    Parameters
    ----------
    path : str
        The file written by ``stringstab identify``.
    vehicle : int, optional
        Keep only the follower at this platoon position.

    Returns
    -------
    list of dict
        Rows with at least position, name, k_x, k_v, k_a, tau, delta, headway, standstill and
        reaction_delay (0 in a file written before θ_r was fitted).

    Raises
    ------
    StringStabError
        If the file is not an ``identify.json`` or the vehicle is not in it.
    """
    import json
    from pathlib import Path

    from ..errors import StringStabError

    need = ("position", "name", "k_x", "k_v", "k_a", "tau", "delta", "headway", "standstill")
    from ..io.text_input import read_text

    expected = "an identify.json written by 'stringstab identify'"
    text = read_text(Path(path), label=f"--from {path!r}", expected=expected)
    try:
        doc = json.loads(text)
    except ValueError as e:
        raise StringStabError(f"--from {path!r}: expected {expected}; got text that is not JSON "
                              f"({e})") from e
    rows = doc.get("vehicles") if isinstance(doc, dict) else None
    if doc.get("command") != "identify" or not isinstance(rows, list) or not rows:  # type: ignore[union-attr]
        raise StringStabError(f"--from {path!r}: expected an identify.json with a non-empty 'vehicles' list")
    for r in rows:
        bad = [k for k in need if k not in r or (k != "name" and not isinstance(r[k], (int, float)))]
        if bad:
            raise StringStabError(f"--from {path!r}: vehicle {r.get('name', '?')!r} lacks numeric {bad}")
    for r in rows:
        theta = r.setdefault("reaction_delay", 0.0)
        if not isinstance(theta, (int, float)) or not theta >= 0:
            raise StringStabError(f"--from {path!r}: vehicle {r.get('name', '?')!r} has reaction_delay "
                                  f"{theta!r}; expected a number of seconds >= 0")
    if vehicle is not None:
        rows = [r for r in rows if r["position"] == vehicle]
        if not rows:
            raise StringStabError(f"--from {path!r}: no follower at position {vehicle}; found positions "
                                  f"{[r['position'] for r in doc['vehicles']]}")
    return rows
