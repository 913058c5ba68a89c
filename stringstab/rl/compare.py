"""The IDL paper's Table 4 layout: one row per strategy, and the reference's improvement over each.

Columns (all "lower is better"): TIT (mean per episode, eqs 31-32), M_CI (eq 34), M_effi
(eq 35), M_lss (eq 30, "stable" when < 1) and M_fss (eq 27, gain strategies only).  The
improvement of the reference strategy R over strategy S in metric m is
100 (m_S − m_R)/m_S % (the paper's "↑" when positive), as in Table 4.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Mapping
from typing import Any

__all__ = ["METRICS", "improvement", "table_csv", "table_markdown", "table_rows"]

#: (summary key, column title) of Table 4.
METRICS: tuple[tuple[str, str], ...] = (("TIT", "TIT"), ("M_CI", "M_CI"), ("M_effi", "M_effi"),
                                        ("M_lss", "M_lss"), ("M_fss", "M_fss (%)"))


def improvement(reference: float | None, other: float | None) -> float | None:
    """100 (other − reference)/other, the reference's gain over ``other`` (None if undefined).

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
    """
    def val(v: Any) -> float | None:
        if isinstance(v, Mapping):
            return v.get("mean")
        return v

    rows: list[dict[str, Any]] = []
    for name, s in summaries.items():
        rows.append({"strategy": name, **{k: s.get(k) for k, _ in METRICS}})
    if reference is not None and reference in summaries:
        ref = summaries[reference]
        for name, s in summaries.items():
            if name == reference:
                continue
            rows.append({"strategy": f"{reference} compared to {name}",
                         **{k: improvement(val(ref.get(k)), val(s.get(k))) if k != "M_fss" else None
                            for k, _ in METRICS}, "improvement": True})
    return rows


def _cell(key: str, v: Any, improvement_row: bool) -> str:
    if v is None:
        return "–"
    if improvement_row:
        return f"{v:+.2f}%"
    if isinstance(v, Mapping):
        return f"{v['mean']:.3g} ± {v['std']:.2g}"
    if key == "M_lss":
        return f"{v:.3f} ({'stable' if v < 1 else 'unstable'})"
    if key == "M_fss":
        return f"{v:.2f}%"
    return f"{v:.3g}"


def table_markdown(rows: list[dict[str, Any]]) -> str:
    """Table 4 as Markdown (improvement rows show ± percentages, positive = reference better)."""
    head = "| strategy | " + " | ".join(t for _, t in METRICS) + " |\n"
    head += "|---|" + "---|" * len(METRICS) + "\n"
    body = "".join(
        f"| {r['strategy']} | "
        + " | ".join(_cell(k, r.get(k), bool(r.get("improvement"))) for k, _ in METRICS) + " |\n"
        for r in rows)
    return head + body


def table_csv(rows: list[dict[str, Any]]) -> str:
    """Table 4 as CSV: metric means (and ``_std`` columns when given), improvements in %."""
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
            else:
                line += ["" if v is None else f"{v:.6g}", ""]
        w.writerow([*line, "improvement_percent" if r.get("improvement") else "value"])
    return buf.getvalue()
