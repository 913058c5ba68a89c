"""The IDL paper's Table 4 layout: one row per strategy, and the reference's improvement over each.

Columns: TIT (mean per episode, eqs 31-32, s²), M_CI (eq 34, m²/s⁶), M_effi (eq 35, s) and
M_lss (eq 30, the mean m_p) — lower is better — and m_fss (eq 27's M_fss as a fraction in
[0, 1]: the share of executed gains certified) — higher is better; a strategy that executes no
certified gain (CACC and IDM in their own form, an acceleration policy) has m_fss 0.  M_lss is shown with the share of episodes whose
m_p exceeds 1 (a mean below 1 does not make every episode damp).  The improvement of the
reference strategy R over strategy S in a lower-is-better metric m is 100 (m_S − m_R)/m_S % (the
paper's "↑" when positive), as in Table 4; where m_S = 0 it is undefined and the row states both
values instead of hiding them.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Mapping
from typing import Any

from ..ranges import metric_caveat

__all__ = ["METRICS", "format_m_fss", "improvement", "table_csv", "table_markdown", "table_rows"]


def format_m_fss(v: Any) -> str:
    """m_fss as every output prints it: a strategy that executes no eq-4 gains has 0.

    CACC and IDM execute no gains of the linear law (IDL eq 4), so none is certified: the
    summary holds None (JSON ``null``), printed ``0 (no certified gains executed)`` on stdout,
    in ``table.md`` and in the report alike.

    Parameters
    ----------
    v : float, mapping with ``mean``/``std``, or None
        The value.

    Returns
    -------
    str
        The text.

    Examples
    --------
    >>> format_m_fss(None), format_m_fss(1.0), format_m_fss(0.98765)
    ('0 (no certified gains executed)', '1', '0.9877')
    """
    if v is None:
        return "0 (no certified gains executed)"
    if isinstance(v, Mapping):
        return f"{v['mean']:.3g} ± {v['std']:.2g}"
    return f"{float(v):.4g}"

#: (summary key, column title) of Table 4.
METRICS: tuple[tuple[str, str], ...] = (("TIT", "TIT (s², ↓)"), ("M_CI", "M_CI (m²/s⁶, ↓)"),
                                        ("M_effi", "M_effi (s, ↓)"), ("M_lss", "M_lss (↓)"),
                                        ("m_fss", "m_fss (fraction, ↑)"))


def improvement(reference: float | None, other: float | None) -> float | None:
    """100 (other − reference)/other, the reference's gain over ``other`` (None if undefined).

    Parameters
    ----------
    reference, other : float or None
        The metric of the reference strategy and of the other one (lower is better).

    Returns
    -------
    float or None
        The improvement in %, None when either is missing or ``other`` is 0.

    Examples
    --------
    >>> round(improvement(0.32, 9.13), 2)
    96.5
    >>> improvement(0.5, 0.0) is None
    True
    """
    if reference is None or other is None or other == 0:
        return None
    return 100.0 * (other - reference) / other


def table_rows(summaries: Mapping[str, Mapping[str, Any]],
               reference: str | None = None) -> list[dict[str, Any]]:
    """Rows of Table 4: every strategy's metrics, then "compared to S" rows for the reference.

    ``summaries`` maps a strategy label to its summary (mean ± spread entries may be given as
    ``{"mean": .., "std": ..}``; the mean is compared).

    Parameters
    ----------
    summaries : mapping
        ``{strategy: summary}`` (keys of :data:`METRICS` and ``share_m_p_below_1``).
    reference : str, optional
        The strategy whose improvements are listed.

    Returns
    -------
    list of dict
        One row per strategy, then one "compared to" row per other strategy (``improvement``
        True; a cell is a % or, where undefined, a sentence).
    """
    def val(v: Any) -> float | None:
        if isinstance(v, Mapping):
            return v.get("mean")
        return v

    rows: list[dict[str, Any]] = []
    for name, s in summaries.items():
        rows.append({"strategy": name, **{k: s.get(k) for k, _ in METRICS},
                     "share_m_p_below_1": s.get("share_m_p_below_1")})
    if reference is not None and reference in summaries:
        ref = summaries[reference]
        for name, s in summaries.items():
            if name == reference:
                continue
            row: dict[str, Any] = {"strategy": f"{reference} compared to {name}", "improvement": True}
            for k, _ in METRICS:
                r, o = val(ref.get(k)), val(s.get(k))
                if k == "m_fss":
                    row[k] = None
                elif o == 0 and r is not None:  # 100 (o − r)/o undefined: say what it hides
                    row[k] = "equal (both 0)" if r == 0 else f"worse: {r:.3g} vs 0"
                else:
                    row[k] = improvement(r, o)
            rows.append(row)
    return rows


def _cell(key: str, v: Any, improvement_row: bool, row: Mapping[str, Any] | None = None) -> str:
    if isinstance(v, str):
        return v
    if v is None:
        if key == "m_fss" and not improvement_row:
            return format_m_fss(v)
        return "–"
    if improvement_row:
        return f"{v:+.2f}%"
    if isinstance(v, Mapping):
        text = f"{v['mean']:.3g} ± {v['std']:.2g}"
    elif key == "m_fss":
        return format_m_fss(v)
    else:
        text = f"{v:.3f}" if key == "M_lss" else f"{v:.3g}"
    caveat = metric_caveat(key, v["mean"] if isinstance(v, Mapping) else v)
    if caveat:
        text += f" {caveat}"
    if key == "M_lss" and row is not None and row.get("share_m_p_below_1") is not None:
        share = row["share_m_p_below_1"]
        share = float(share.get("mean", 0.0) if isinstance(share, Mapping) else share)
        text += (" (m_p < 1 in every episode)" if share >= 1.0
                 else f" (m_p > 1 in {100 * (1 - share):.0f}% of episodes)")
    return text


def table_markdown(rows: list[dict[str, Any]]) -> str:
    """Table 4 as Markdown (improvement rows show ± percentages, positive = reference better).

    Parameters
    ----------
    rows : list of dict
        From :func:`table_rows`.

    Returns
    -------
    str
        The Markdown table.
    """
    head = "| strategy | " + " | ".join(t for _, t in METRICS) + " |\n"
    head += "|---|" + "---|" * len(METRICS) + "\n"
    body = "".join(
        f"| {r['strategy']} | "
        + " | ".join(_cell(k, r.get(k), bool(r.get("improvement")), r) for k, _ in METRICS)
        + " |\n"
        for r in rows)
    return head + body


def table_csv(rows: list[dict[str, Any]]) -> str:
    """Table 4 as CSV: metric means (and ``_std`` columns when given), improvements in %.

    Parameters
    ----------
    rows : list of dict
        From :func:`table_rows`.

    Returns
    -------
    str
        The CSV text (an undefined improvement is an empty cell).
    """
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    cols = ["strategy"]
    for k, _ in METRICS:
        cols += [k, f"{k}_std"]
    w.writerow([*cols, "kind"])
    for r in rows:
        line = [r["strategy"]]
        for k, _ in METRICS:
            v = r.get(k)
            if isinstance(v, Mapping):
                line += [f"{v['mean']:.6g}", f"{v['std']:.6g}"]
            elif isinstance(v, str):  # an undefined improvement, stated in words
                line += ["", ""]
            else:
                line += ["" if v is None else f"{v:.6g}", ""]
        w.writerow([*line, "improvement_percent" if r.get("improvement") else "value"])
    return buf.getvalue()
