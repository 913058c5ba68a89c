r"""Physically meaningful magnitudes of the toolkit's inputs: warned beyond, refused far beyond.

Each quantity has a *sensible* range (the values a car-following study uses; beyond it a
command runs and says so on stderr) and an *absurd* bound (beyond it no vehicle exists and the
numerics lose their meaning — the certificate's polynomial coefficients are products of up to
four gains and powers of τ, δ, T* up to 6, so 1e308 overflows to inf — and the input is refused
with :class:`~stringstab.errors.StringStabError` before any solver sees it).

=============  ================  ============  ==========================================
quantity       sensible          refused       why
=============  ================  ============  ==========================================
gain k         \|k\| <= 10        \|k\| > 1e6    IDL Table 2: [−2, 2]; 1e6 1/s² turns 1 m of
                                               spacing error into 1e6 m/s²
τ              (0, 2] s          > 100 s       actuator lags are 0.1-1 s
δ              [0, 2] s          > 100 s       V2V delays are 0.01-0.5 s
T*             [0, 5] s          > 100 s       time headways are 0.3-3 s
θ_r            [0, 2] s          > 100 s       reaction/actuation delays: ACC 0.1-0.6 s,
                                               drivers 0.5-1.5 s
H              (0, 1] s          > 100 s       control periods are 0.01-0.2 s
duration       <= 1 day          > 1 year      a run, an episode, a cycle
=============  ================  ============  ==========================================
"""

from __future__ import annotations

import math
from typing import Any

from .errors import StringStabError

__all__ = ["LEADER_ACCEL_ABSURD", "LEADER_SPEED_ABSURD", "METRIC_RANGES", "RANGES", "check_magnitude",
           "metric_caveat", "sensible_warning"]

#: A leader (or a speed limit) faster than this, m/s (252 km/h), is no road vehicle: refused.
LEADER_SPEED_ABSURD = 70.0
#: A leader (or an acceleration limit) beyond ±this, m/s² (1.5 g), is no road vehicle: refused.
LEADER_ACCEL_ABSURD = 15.0

#: name -> (sensible upper bound, refused above, unit, what it is)
RANGES: dict[str, tuple[float, float, str, str]] = {
    "gain": (10.0, 1e6, "", "gain"),
    "tau": (2.0, 100.0, " s", "actuator lag tau"),
    "delta": (2.0, 100.0, " s", "communication delay delta"),
    "headway": (5.0, 100.0, " s", "time headway T*"),
    "reaction_delay": (2.0, 100.0, " s", "reaction delay theta_r"),
    "sample_time": (1.0, 100.0, " s", "sample time H"),
    "duration": (86_400.0, 3.2e7, " s", "duration"),
}


def check_magnitude(kind: str, value: Any, *, name: str | None = None) -> float:
    """``value`` as a float, refused when its magnitude is beyond :data:`RANGES` ``[kind]``.

    Parameters
    ----------
    kind : str
        A key of :data:`RANGES` (``gain``, ``tau``, ``delta``, ``headway``,
        ``reaction_delay``, ``sample_time``, ``duration``).
    value : float
        The number (already checked finite by the caller's own parser; NaN is refused too).
    name : str, optional
        How the message names it (default: the quantity's name).

    Returns
    -------
    float

    Raises
    ------
    StringStabError
        When ``|value|`` exceeds the refusal bound, with the sensible range.

    Examples
    --------
    >>> check_magnitude("tau", 0.1)
    0.1
    >>> check_magnitude("tau", 1e300)
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: actuator lag tau = 1e+300 s is far outside the physically meaningful range (sensible: up to 2 s; refused above 100 s)
    """
    _sensible, absurd, unit, what = RANGES[kind]
    x = float(value)
    if not abs(x) <= absurd:
        raise StringStabError(
            f"{name or what} = {x:g}{unit} is far outside the physically meaningful range "
            f"(sensible: {_range(kind)}; refused above {absurd:g}{unit})")
    return x


def sensible_warning(kind: str, value: Any, *, name: str | None = None) -> str | None:
    """A one-sentence warning when ``value`` is beyond the sensible range of ``kind``, else None.

    Parameters
    ----------
    kind : str
        A key of :data:`RANGES` (``gain``, ``tau``, ``delta``, ``headway``, ``sample_time``,
        ``duration``).
    value : float
        The number; NaN and ±inf give no warning (they are the parsers' to refuse).
    name : str, optional
        How to name the value in the sentence (default: the description in :data:`RANGES`).

    Returns
    -------
    str or None
        The warning, or None when |value| is within the sensible bound.

    Examples
    --------
    >>> sensible_warning("gain", 0.5) is None
    True
    >>> sensible_warning("gain", 50.0, name="k_x")
    'k_x = 50 is outside the sensible range (|k| up to 10; the IDL paper uses [-2, 2]); the result is computed but describes no practical vehicle or controller'
    """
    sensible, _, unit, what = RANGES[kind]
    x = float(value)
    if not math.isfinite(x) or abs(x) <= sensible:
        return None
    extra = "; the IDL paper uses [-2, 2]" if kind == "gain" else ""
    return (f"{name or what} = {x:g}{unit} is outside the sensible range ({_range(kind)}{extra}); "
            "the result is computed but describes no practical vehicle or controller")


def _range(kind: str) -> str:
    sensible, _, unit, _ = RANGES[kind]
    return f"|k| up to {sensible:g}" if kind == "gain" else f"up to {sensible:g}{unit}"


#: The sensible range of each reported metric: name -> (lo, hi, unit, what a value outside means).
#: A number outside is printed with :func:`metric_caveat` beside it (docs/conventions.md).
METRIC_RANGES: dict[str, tuple[float, float, str, str]] = {
    "M_effi": (0.0, math.inf, "s", "a negative mean time headway means some moment has a "
               "negative gap (a collision or an overlap), so it measures no efficiency"),
    "max_m_p": (0.0, 10.0, "", "a predecessor that barely accelerates makes the energy ratio "
                "meaningless"),
    "M_lss": (0.0, 10.0, "", "a predecessor that barely accelerates makes the energy ratio "
              "meaningless"),
    "TIT": (0.0, math.inf, "s²", "a time integral of positive terms cannot be negative"),
    "M_CI": (0.0, 60.0, "m²/s⁶", "beyond the top of the IDL paper's Fig. 11 ranges"),
    "m_fss": (0.0, 1.0, "", "a share lies in [0, 1]"),
    "certified_row_share": (0.0, 1.0, "", "a share lies in [0, 1]"),
}


def metric_caveat(name: str, value: Any) -> str:
    """What to print beside a metric outside its sensible range ("" inside it or unknown).

    Parameters
    ----------
    name : str
        The metric's key (``"M_effi"``, ``"max_m_p"``, ...; see :data:`METRIC_RANGES`).
    value : float or None
        Its value (None, non-numbers and names without a range give "").

    Returns
    -------
    str
        ``""`` or a parenthesised caveat naming the range, e.g. ``"(outside the sensible
        range [0, 10] s: ...)"``.

    Examples
    --------
    >>> metric_caveat("M_effi", 1.47)
    ''
    >>> metric_caveat("M_effi", -20.1)[:46]
    '(outside the sensible range [0, ∞] s: a negati'
    """
    if name not in METRIC_RANGES or isinstance(value, bool):
        return ""
    try:
        x = float(value)
    except (TypeError, ValueError):
        return ""
    lo, hi, unit, why = METRIC_RANGES[name]
    if not math.isfinite(x) or lo <= x <= hi:
        return ""
    top = "∞" if math.isinf(hi) else f"{hi:g}"
    return f"(outside the sensible range [{lo:g}, {top}]{' ' + unit if unit else ''}: {why})"
