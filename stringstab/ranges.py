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
H              [1e-3, 1] s       < 1e-4 s,     control periods are 0.01-0.2 s; the sampled
                                 > 100 s       loop's order grows as δ/H (H = 1e-300 s
                                               divided by zero, 1e-8 s ran for ever)
dt             [1e-3, 1] s       < 1e-4 s,     simulation steps are 0.01-0.1 s; the run's
                                 > 100 s       samples grow as 1/dt (2e-308 s overflowed)
duration       <= 1 day          > 1 year      a run, an episode, a cycle
jerk limit J   <= 30 m/s³        > 1e6 m/s³    HCFS: 2 a_max / T = 30 m/s³ is what the
                                               ±3 m/s² bounds alone guarantee at T = 0.2 s
length         <= 30 m           > 10 km       vehicles are 3-25 m long; l0 is 1-10 m
TTC*           <= 10 s           > 1 hour      TTC thresholds are 1.5-5 s
weight         <= 1000           > 1e6         distance weights are ratios near 1
margin         <= 1              > 1e6         the repair's margins: 1e-3 and 1e-4 by default
burst          <= 100 messages   > 1e6         Gilbert-Elliott bursts of a few messages
speed noise σ  <= 5 m/s          > 70 m/s      speed sensors err by cm/s; 70 m/s is no road
                                               vehicle's speed
=============  ================  ============  ==========================================

Counts (:data:`COUNTS`: a seed, steps, workers, refits, orders) have an upper bound of the same
kind: beyond the sensible one a command warns that the run will be long or pointless, beyond the
largest one it refuses (:func:`check_count`), so ``--bootstrap 1e20`` is a sentence, not a run
that never ends.
"""

from __future__ import annotations

import math
from typing import Any

from .errors import StringStabError

__all__ = ["COUNTS", "FLOORS", "LEADER_ACCEL_ABSURD", "LEADER_SPEED_ABSURD", "METRIC_RANGES",
           "MIN_LEADER_SECONDS", "RANGES", "check_count", "check_magnitude", "count_warning",
           "metric_caveat", "sensible_warning"]

#: A leader (or a speed limit) faster than this, m/s (252 km/h), is no road vehicle: refused.
LEADER_SPEED_ABSURD = 70.0
#: A leader (or an acceleration limit) beyond ±this, m/s² (1.5 g), is no road vehicle: refused.
LEADER_ACCEL_ABSURD = 15.0
#: A leader shorter than this, s, is refused (a car-following response needs seconds to show;
#: :func:`stringstab.traffic.check_leader` also asks for the controller's settling time).
MIN_LEADER_SECONDS = 10.0

#: name -> (sensible upper bound, refused above, unit, what it is)
RANGES: dict[str, tuple[float, float, str, str]] = {
    "gain": (10.0, 1e6, "", "gain"),
    "tau": (2.0, 100.0, " s", "actuator lag tau"),
    "delta": (2.0, 100.0, " s", "communication delay delta"),
    "headway": (5.0, 100.0, " s", "time headway T*"),
    "reaction_delay": (2.0, 100.0, " s", "reaction delay theta_r"),
    "sample_time": (1.0, 100.0, " s", "sample time H"),
    "step": (1.0, 100.0, " s", "simulation step dt"),
    "duration": (86_400.0, 3.2e7, " s", "duration"),
    "jerk": (30.0, 1e6, " m/s³", "jerk limit J"),
    "length": (30.0, 1e4, " m", "length"),
    "ttc": (10.0, 3600.0, " s", "TTC* threshold"),
    "weight": (1000.0, 1e6, "", "weight"),
    "margin": (1.0, 1e6, "", "margin"),
    "burst": (100.0, 1e6, " messages", "mean burst of lost messages"),
    "speed_noise": (5.0, 70.0, " m/s", "speed noise sigma"),
}

#: name -> (sensible lower bound, refused below): the magnitudes that also have a floor.
FLOORS: dict[str, tuple[float, float]] = {
    "sample_time": (1e-3, 1e-4),
    "step": (1e-3, 1e-4),
}

#: name -> (sensible upper bound, largest accepted, what is counted, why the largest)
COUNTS: dict[str, tuple[int, int, str, str]] = {
    "seed": (2**32 - 1, 2**32 - 1, "seed", "seeds are 32-bit"),
    "steps": (10**8, 10**10, "environment steps", "about a year at 300 steps/s"),
    "episodes": (10**6, 10**10, "episodes", "more than any step budget ends"),
    "followers": (1_000, 10**6, "followers", "the IDL paper's platoons have 10 and 100"),
    "platoons": (1_000, 10**6, "platoons", "each platoon is simulated at every step"),
    "workers": (256, 4_096, "worker processes", "more than any machine's cores"),
    "retries": (10, 1_000, "retries", "a task that fails this often will not succeed"),
    "order": (20, 100, "order", "higher orders lose every digit to round-off"),
    "refits": (10_000, 10**6, "refits", "each refit is a full identification"),
    "starts": (100, 10_000, "starts", "each start is a full fit"),
    "iterations": (10**5, 10**8, "iterations", "each iteration certifies a region"),
    "grid": (100, 1_000, "grid intervals", "a region is a (2N + 1)^3 grid"),
    "dpi": (1_200, 2_400, "dots per inch", "a 2400 dpi map is 15,000 pixels wide"),
    "message_steps": (100, 200, "control steps per message (N = P/H)",
                      "the lifted link's matrices grow with N: N = 100 took 1.3 GB and 13 s, "
                      "N = 400 more than 14 GB"),
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
    if kind in FLOORS and 0 < abs(x) < FLOORS[kind][1]:
        raise StringStabError(
            f"{name or what} = {x:g}{unit} is far outside the physically meaningful range "
            f"(sensible: {_range(kind)}; refused below {FLOORS[kind][1]:g}{unit})")
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
    low = FLOORS.get(kind, (0.0, 0.0))[0]
    if not math.isfinite(x) or low <= abs(x) <= sensible or x == 0:
        return None
    extra = "; the IDL paper uses [-2, 2]" if kind == "gain" else ""
    return (f"{name or what} = {x:g}{unit} is outside the sensible range ({_range(kind)}{extra}); "
            "the result is computed but describes no practical vehicle or controller")


def check_count(kind: str, value: int, *, name: str) -> int:
    """``value``, refused when it exceeds the largest count of ``kind`` in :data:`COUNTS`.

    Parameters
    ----------
    kind : str
        A key of :data:`COUNTS` (``seed``, ``steps``, ``workers``, ``order``, ...).
    value : int
        The count (its lower bound is the caller's to check).
    name : str
        How the message names it (the option, e.g. ``"--bootstrap"``).

    Returns
    -------
    int

    Raises
    ------
    StringStabError
        When ``value`` exceeds the largest count accepted, with the reason.

    Examples
    --------
    >>> check_count("refits", 200, name="--bootstrap")
    200
    >>> check_count("refits", 10**20, name="--bootstrap")
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: --bootstrap must be at most 1000000 refits (each refit is a full identification); got 100000000000000000000
    """
    _sensible, largest, what, why = COUNTS[kind]
    if value > largest:
        raise StringStabError(f"{name} must be at most {largest} {what} ({why}); got {value}")
    return value


def count_warning(kind: str, value: int, *, name: str) -> str | None:
    """A one-sentence warning when ``value`` is beyond the sensible count of ``kind``, else None.

    Parameters
    ----------
    kind : str
        A key of :data:`COUNTS`.
    value : int
        The count.
    name : str
        How the sentence names it (the option).

    Returns
    -------
    str or None
        The warning, or None within the sensible bound.

    Examples
    --------
    >>> count_warning("refits", 50, name="--bootstrap") is None
    True
    >>> count_warning("refits", 50_000, name="--bootstrap")
    '--bootstrap 50000 is more than the sensible 10000 refits; the run is computed but will take long'
    """
    sensible, _, what, _ = COUNTS[kind]
    if value <= sensible:
        return None
    return (f"{name} {value} is more than the sensible {sensible} {what}; the run is computed but "
            "will take long")


def _range(kind: str) -> str:
    sensible, _, unit, _ = RANGES[kind]
    if kind in FLOORS:
        return f"{FLOORS[kind][0]:g} to {sensible:g}{unit}"
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
