"""How identify words its verdicts and notes: never more confidently than the evidence.

* :func:`supported_verdict` — the verdict of a follower or a car: ``certified`` only when the
  point fit *and every bootstrap refit* are certified, ``not_certified`` only when all are not
  certified, ``inconclusive`` otherwise (a mixture, or an inconclusive certificate);
* :func:`statement` — the same in words, with the share of refits certified;
* :func:`profile_note` — what a profile over T* or θ_r shows, computed from its rows;
* :func:`model_only` — a string-instability peak below the data's lowest resolved frequency
  is the model's extrapolation, not something the log measured.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from ..certify.verdicts import Verdict

__all__ = ["model_only", "profile_note", "statement", "supported_verdict"]


def supported_verdict(point_verdict: str, boot: Sequence[str]) -> Verdict:
    """The verdict the bootstrap supports.

    Parameters
    ----------
    point_verdict : str
        The certificate's verdict on the point fit.
    boot : sequence of str
        The certificates' verdicts on the bootstrap refits (empty: no bootstrap).

    Returns
    -------
    Verdict
        ``CERTIFIED`` (``NOT_CERTIFIED``) when the point fit and every refit are certified
        (not certified); ``INCONCLUSIVE`` otherwise.  Without a bootstrap, the point verdict
        (its statement says no uncertainty was measured).

    Examples
    --------
    >>> supported_verdict("certified", ["certified"] * 37 + ["not_certified"] * 13).value
    'inconclusive'
    >>> supported_verdict("not_certified", ["not_certified"] * 50).value
    'not_certified'
    """
    point = Verdict(str(point_verdict))
    if not boot:
        return point
    if all(str(b) == point.value for b in boot) and point is not Verdict.INCONCLUSIVE:
        return point
    return Verdict.INCONCLUSIVE


def statement(point_verdict: str, boot: Sequence[str], at_bound: Sequence[str] = (),
              model_only_note: str = "") -> str:
    """The verdict worded no more confidently than the bootstrap allows.

    Parameters
    ----------
    point_verdict : str
        Verdict of the point fit: ``"certified"``, ``"not_certified"`` or ``"inconclusive"``
        (only worded when there is no bootstrap).
    boot : sequence of str
        Verdicts of the bootstrap refits; empty when no bootstrap was run.
    at_bound : sequence of str, optional
        Names of the parameters whose fit stopped at the bound of its search box; appended
        as a caveat.
    model_only_note : str, optional
        :func:`model_only`'s words, appended when the peak is below the resolved band.

    Returns
    -------
    str
        "string stable in n of n bootstrap fits" / "not string stable in n of n ..." when the
        point fit and all refits agree, otherwise "inconclusive: p % of fits certified";
        without a bootstrap, the point verdict qualified as unmeasured.

    Examples
    --------
    >>> statement("not_certified", ["not_certified"] * 50)
    'not string stable in 50 of 50 bootstrap fits'
    >>> statement("certified", ["certified"] * 61 + ["not_certified"] * 39)
    'inconclusive: 61 % of fits certified'
    >>> statement("certified", [])
    'certified at the point estimate (no bootstrap: no uncertainty measured)'
    """
    n = len(boot)
    if n == 0:
        words = {"certified": "certified", "not_certified": "not certified",
                 "inconclusive": "inconclusive"}[str(point_verdict)]
        text = f"{words} at the point estimate (no bootstrap: no uncertainty measured)"
    else:
        c = sum(str(v) == Verdict.CERTIFIED for v in boot)
        v = supported_verdict(point_verdict, boot)
        if v is Verdict.CERTIFIED:
            text = f"string stable in {n} of {n} bootstrap fits"
        elif v is Verdict.NOT_CERTIFIED:
            text = f"not string stable in {n} of {n} bootstrap fits"
        else:
            text = f"inconclusive: {round(100 * c / n)} % of fits certified"
            if c in (0, n) and str(point_verdict) != ("certified" if c else "not_certified"):
                text += f" (the point fit: {point_verdict})"
    if at_bound:
        text += f" (fit at the bound of {', '.join(at_bound)})"
    if model_only_note:
        text += f" ({model_only_note})"
    return text


def model_only(verdict: str, peak_omega: float, lowest_resolved: float) -> str:
    """Words for a string-instability peak the data cannot see, or "".

    Parameters
    ----------
    verdict : str
        The certificate's verdict.
    peak_omega : float
        Where sup|Γ(jω)| is reached, rad/s.
    lowest_resolved : float
        The data's lowest resolved frequency (the first Welch bin above 0), rad/s.

    Returns
    -------
    str
        Empty unless the fit is not certified with its peak below ``lowest_resolved``.

    Examples
    --------
    >>> model_only("not_certified", 0.05, 0.12)
    'model-only: the peak at 0.05 rad/s is below the lowest frequency the log resolves, 0.12 rad/s'
    """
    if (str(verdict) == Verdict.NOT_CERTIFIED and math.isfinite(peak_omega) and math.isfinite(lowest_resolved)
            and 0 < peak_omega < lowest_resolved):
        return (f"model-only: the peak at {peak_omega:.3g} rad/s is below the lowest frequency the "
                f"log resolves, {lowest_resolved:.3g} rad/s")
    return ""


def profile_note(rows: list[dict[str, Any]], best_rmse: float, point_verdict: str, *,
                 name: str = "headway", symbol: str = "T*") -> str:
    """What a profile shows, from its rows: whether the verdict depends on the profiled value.

    Parameters
    ----------
    rows : list of dict
        One per held value: ``name`` (the value), ``verdict``, ``sup_gain``, ``rmse_speed``;
        ``rmse_speed_increase`` is added to each (relative to ``best_rmse``).
    best_rmse : float
        The point fit's speed RMSE, m/s.
    point_verdict : str
        The point fit's verdict (compared with every row's).
    name, symbol : str
        The profiled parameter's key in the rows and how the note writes it.

    Returns
    -------
    str
        "the verdict is V at every value ..." only when every row's verdict and the point
        fit's are the same (and every refit converged); otherwise each value with its verdict
        (a refit more than 10 times the point fit's speed RMSE is called diverged).

    Examples
    --------
    >>> rows = [{"headway": 0.0, "verdict": "not_certified", "sup_gain": 1.3, "rmse_speed": 0.3},
    ...         {"headway": 1.0, "verdict": "certified", "sup_gain": 1.0, "rmse_speed": 0.33}]
    >>> profile_note(rows, 0.3, "not_certified").startswith("profile over T*: the verdict depends on T*")
    True
    """
    for r in rows:
        r["rmse_speed_increase"] = r["rmse_speed"] / best_rmse - 1.0 if best_rmse > 0 else math.nan

    def inc(r: dict[str, Any]) -> str:
        x = r["rmse_speed_increase"]
        return (f"speed RMSE {100 * x:+.1f} %" if math.isfinite(x) and x <= 10 else
                "no fit found: the refitted loop diverges")

    verdicts = [str(r["verdict"]) for r in rows]
    values = ", ".join(f"{r[name]:g}" for r in rows)
    fair = [r for r in rows if math.isfinite(r["rmse_speed_increase"]) and r["rmse_speed_increase"] <= 10]
    incs = [100 * r["rmse_speed_increase"] for r in fair]
    sups = [r["sup_gain"] for r in fair]
    if len(set(verdicts) | {str(point_verdict)}) == 1 and len(fair) == len(rows):
        return (f"profile over {symbol}: with {symbol} held at {values} s (the others refitted; speed "
                f"RMSE {min(incs):+.1f} to {max(incs):+.1f} % of the point fit's, sup|Γ| "
                f"{min(sups):.4g}-{max(sups):.4g}) the verdict is {verdicts[0]} at every value, as at "
                f"the point fit: the {symbol} ambiguity does not change it")
    which = "; ".join(f"{symbol} = {r[name]:g} s: {r['verdict']}, sup|Γ| {r['sup_gain']:.4g} ({inc(r)})"
                      for r in rows)
    return (f"profile over {symbol}: the verdict depends on {symbol} (the point fit: {point_verdict}; "
            f"the others refitted at each value, speed RMSE relative to the point fit's): {which}")
