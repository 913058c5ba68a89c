r"""The head-to-tail certificate of one string: its verdict, its vehicles' and its worst sub-string.

:func:`certify_string_kernel` (reached through :func:`stringstab.certify.api.certify_string`)
answers, for N followers in order behind a leader:

* **head to tail** — the string's verdict (:mod:`stringstab.certify.head_to_tail`,
  :mod:`stringstab.certify.head_to_tail_sampled`): ``certified`` when every vehicle is
  internally stable and sup_ω ∏_i |Γ_i(jω)| ≤ 1 is proven; ``not_certified`` when a vehicle is
  surely not internally stable or a witness ω has ∏_i |Γ_i(jω)| > 1; ``inconclusive``
  otherwise; with sup ∏|Γ_i| and where it is found (reporting only);
* **each vehicle** — its own certificate (:mod:`stringstab.certify.continuous`, or
  :mod:`stringstab.certify.sampled` with the predecessor's lag);
* **the worst sub-string** — among the runs of consecutive vehicles (i..j), the longest one
  whose product is *proven* to exceed 1 somewhere: its head-to-tail verdict is
  ``not_certified`` (a witness frequency, or a vehicle not internally stable); ties go to the
  larger sup.  When no run is proven to exceed 1 but some are undecided, the longest
  ``inconclusive`` run is reported instead (with that verdict); when every run is certified,
  there is none.  A run of one vehicle carries that vehicle's own verdict; every run of two or
  more is certified by the same head-to-tail certificate as the whole string.

References
----------
IDL paper, Definition 1 (eq 10); issue 27 (head-to-tail certificates of recorded strings).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import StringStabError, show
from ..params import Params, as_gains, check_reaction_delay, positive
from ..params import sample_time as checked_sample_time
from . import continuous
from .head_to_tail import MAX_VEHICLES, ContinuousString, StringArrays, StringLoop, Vehicle
from .string_decision import StringDecision, decide
from .verdicts import CERTIFIED, INCONCLUSIVE, NOT_CERTIFIED, VERDICTS, Verdict, num

__all__ = [
    "OPTIONAL",
    "REQUIRED",
    "StringCertificate",
    "Substring",
    "certify_string_kernel",
    "check_vehicles",
    "default_grid",
    "worst_substring",
]


def default_grid(length: int) -> int:
    """Initial intervals of the branch and bound for a string of ``length`` vehicles.

    Parameters
    ----------
    length : int
        N, the vehicles of the string.

    Returns
    -------
    int
        64 + 8N: each vehicle's delays add oscillations to the product.
    """
    return 64 + 8 * int(length)


@dataclass(frozen=True)
class Substring:
    """A run of consecutive vehicles first..last (positions, the leader is 0) and its verdict.

    Attributes
    ----------
    first, last : int
        Positions of its first and last vehicle (1-based, as in the string).
    verdict : str
        Its head-to-tail verdict.
    sup_gain : float
        sup ∏|Γ_i| over the run found (``inf`` when a vehicle is not internally stable).
    peak_omega : float
        Where, rad/s.
    """

    first: int
    last: int
    verdict: str
    sup_gain: float
    peak_omega: float

    @property
    def length(self) -> int:
        """The number of vehicles of the run."""
        return self.last - self.first + 1

    def as_dict(self) -> dict[str, Any]:
        """The JSON form (non-finite numbers as None).

        Returns
        -------
        dict
            ``first``, ``last``, ``length``, ``verdict``, ``sup_gain``, ``peak_omega``.
        """
        return {"first": self.first, "last": self.last, "length": self.length,
                "verdict": self.verdict, "sup_gain": num(self.sup_gain),
                "peak_omega": num(self.peak_omega)}


@dataclass(frozen=True)
class StringCertificate:
    """The head-to-tail certificate of one string (module docstring).

    Attributes
    ----------
    vehicles : tuple of Vehicle
        The followers, from the head.
    certificates : tuple
        Each vehicle's own certificate (:class:`~stringstab.certify.continuous.Certificate` or
        :class:`~stringstab.certify.sampled.SampledCertificate`).
    verdict : str
        The head-to-tail verdict.
    reason : str
        Why, in words.
    sup_gain : float
        sup_ω ∏|Γ_i(jω)| found (1, at ω = 0, when certified; ``inf`` when a vehicle is not
        internally stable).
    peak_omega : float
        Where, rad/s.
    witness_omega : float
        For a not-certified string of internally stable vehicles: a frequency (rad/s) where
        ∏|Γ_i| > 1 is proven; NaN otherwise.
    omega_max : float
        The branch and bound's domain: Ω (rad/s) beyond which G > 0 is proven, or π/H.
    n_evals : int
        Evaluations of the margin G.
    sample_time : float or None
        H of the sampled-data loop, s.
    leader_tau : float or None
        The leader's lag (the first follower's predecessor), sampled loop only, s.
    worst_substring : Substring or None
        Module docstring.
    substrings : tuple of Substring
        Every run examined (all runs of two or more vehicles, and each vehicle alone).
    """

    vehicles: tuple[Vehicle, ...]
    certificates: tuple[Any, ...]
    verdict: str
    reason: str
    sup_gain: float
    peak_omega: float
    witness_omega: float
    omega_max: float
    n_evals: int
    sample_time: float | None = None
    leader_tau: float | None = None
    worst_substring: Substring | None = None
    substrings: tuple[Substring, ...] = field(default=())

    @property
    def certified(self) -> bool:
        """True iff the head-to-tail verdict is ``certified``."""
        return self.verdict == Verdict.CERTIFIED

    def vehicle_rows(self) -> list[dict[str, Any]]:
        """One row per vehicle: position, name, gains, parameters and its own verdict.

        Returns
        -------
        list of dict
            ``position`` (1-based), ``name``, ``k_x``, ``k_v``, ``k_a``, ``tau``, ``delta``,
            ``headway`` (``reaction_delay`` when > 0), ``verdict``, ``stable`` (internal
            stability, surely), ``sup_gain``, ``peak_omega``.
        """
        rows = []
        for i, (v, c) in enumerate(zip(self.vehicles, self.certificates), start=1):
            stable = c.hurwitz if hasattr(c, "hurwitz") else c.schur
            row: dict[str, Any] = {"position": i, "name": v.name, "k_x": v.k_x, "k_v": v.k_v,
                                   "k_a": v.k_a, **v.params.as_dict()}
            row.update({"verdict": str(c.verdict), "stable": bool(stable),
                        "sup_gain": num(float(c.sup_gain)), "peak_omega": num(float(c.peak_omega))})
            rows.append(row)
        return rows

    def head_to_tail(self) -> dict[str, Any]:
        """The ``head_to_tail`` object of the JSON output.

        Returns
        -------
        dict
            ``verdict``, ``reason``, ``sup_gain``, ``peak_omega``, ``witness_omega``,
            ``omega_max``, ``worst_substring`` (an object or None), ``sample_time`` (when
            sampled, with ``leader_tau``) and ``n_vehicles``.
        """
        out: dict[str, Any] = {
            "verdict": self.verdict, "reason": self.reason, "sup_gain": num(self.sup_gain),
            "peak_omega": num(self.peak_omega), "witness_omega": num(self.witness_omega),
            "omega_max": num(self.omega_max), "n_vehicles": len(self.vehicles),
            "worst_substring": None if self.worst_substring is None else self.worst_substring.as_dict(),
        }
        if self.sample_time is not None:
            out["sample_time"] = self.sample_time
            out["leader_tau"] = self.leader_tau
        return out

    def as_dict(self) -> dict[str, Any]:
        """``{"head_to_tail": ..., "vehicles": [...]}``: the JSON of ``stringstab platoon certify``.

        Returns
        -------
        dict
            :meth:`head_to_tail` and :meth:`vehicle_rows`.
        """
        return {"head_to_tail": self.head_to_tail(), "vehicles": self.vehicle_rows()}


# ---------------------------------------------------------------------------
# The checks of the way in
# ---------------------------------------------------------------------------
#: The fields of a vehicle given as a mapping: required, then optional.
REQUIRED = ("k_x", "k_v", "k_a", "tau", "delta", "headway")
OPTIONAL = ("reaction_delay", "name")


def _vehicle(i: int, v: Any) -> Vehicle:
    label = f"vehicle {i}"
    if isinstance(v, Vehicle):
        rec: dict[str, Any] = {"k_x": v.k_x, "k_v": v.k_v, "k_a": v.k_a, "name": v.name,
                               **v.params.as_dict()}
    elif isinstance(v, Mapping):
        rec = dict(v)
    else:
        raise StringStabError(f"{label} must be a Vehicle or a mapping with the fields "
                              f"{', '.join(REQUIRED)}; got {show(v)}")
    name = rec.get("name")
    if name is not None and str(name):
        label += f" ({name})"
    missing = [k for k in REQUIRED if rec.get(k) is None]
    if missing:
        raise StringStabError(f"{label}: missing {', '.join(missing)} (each vehicle needs "
                              f"{', '.join(REQUIRED)})")
    try:
        kx, kv, ka = (float(np.asarray(g).item()) for g in as_gains(rec["k_x"], rec["k_v"], rec["k_a"]))
        theta = check_reaction_delay(rec.get("reaction_delay") or 0.0)
        p = Params(rec["tau"], rec["delta"], rec["headway"], theta)
    except (StringStabError, TypeError, ValueError) as e:
        raise StringStabError(f"{label}: {e}") from e
    return Vehicle(kx, kv, ka, p, "" if name is None else str(name))


def check_vehicles(vehicles: Any, *, sample_time: Any = None,
                   leader_tau: Any = None) -> tuple[tuple[Vehicle, ...], float | None, float | None]:
    """The string, its sample time and leader lag, checked (the way in's checks).

    Parameters
    ----------
    vehicles : sequence of Vehicle or mapping
        The followers, from the head; a mapping has ``k_x, k_v, k_a, tau, delta, headway``
        (optional ``reaction_delay``, ``name``).
    sample_time : float, optional
        H > 0, s.
    leader_tau : float, optional
        The leader's lag τ_0 > 0, s (sampled loop only).

    Returns
    -------
    (tuple of Vehicle, float or None, float or None)

    Raises
    ------
    StringStabError
        One line saying which vehicle and what was expected: fewer than 2 or more than
        :data:`~stringstab.certify.head_to_tail.MAX_VEHICLES` vehicles, a missing, non-finite
        or out-of-range value, a bad sample time, reaction delays that differ between the
        vehicles of a sampled string (:mod:`stringstab.certify.head_to_tail_reaction`).

    Examples
    --------
    >>> check_vehicles([{"k_x": 1, "k_v": 1, "k_a": 0, "tau": 0.1, "delta": 0, "headway": 1}])
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: a string needs at least 2 vehicles (followers of the leader, in order); got 1
    """
    if isinstance(vehicles, (str, bytes, Mapping)) or not isinstance(vehicles, Iterable):
        raise StringStabError(f"vehicles must be a sequence of vehicles; got {show(vehicles)}")
    vs = list(vehicles)
    if len(vs) < 2:
        raise StringStabError("a string needs at least 2 vehicles (followers of the leader, in "
                              f"order); got {len(vs)}")
    if len(vs) > MAX_VEHICLES:
        raise StringStabError(f"a string has at most {MAX_VEHICLES} vehicles; got {len(vs)}")
    out = tuple(_vehicle(i, v) for i, v in enumerate(vs, start=1))
    H = None if sample_time is None else checked_sample_time(sample_time)
    if H is not None:  # θ_r common to a sampled string (head_to_tail_reaction)
        from .head_to_tail_reaction import check_common_reaction_delay

        check_common_reaction_delay(out)
    if leader_tau is not None and H is None:
        raise StringStabError("leader_tau (the leader's lag) is for the sampled loop; got it "
                              "without sample_time")
    lt = None if leader_tau is None else positive("leader_tau (the leader's actuator lag)",
                                                   leader_tau, unit=" s")
    return out, H, lt


# ---------------------------------------------------------------------------
# The kernel
# ---------------------------------------------------------------------------
def _loop(strings: Sequence[Sequence[Vehicle]], sample_time: float | None,
          leader_taus: Sequence[float]) -> StringLoop:
    arrays = StringArrays.of(strings)
    if sample_time is None:
        return ContinuousString(arrays)
    from .head_to_tail_sampled import SampledString

    return SampledString(arrays, sample_time, np.asarray(leader_taus, dtype=float))


def _vehicle_certificates(vehicles: Sequence[Vehicle], sample_time: float | None,
                          leader_tau: float | None) -> tuple[Any, ...]:
    out: list[Any] = []
    for i, v in enumerate(vehicles):
        kx, kv, ka = (np.array([x]) for x in (v.k_x, v.k_v, v.k_a))
        p = v.params
        if sample_time is None and p.reaction_delay > 0:
            from . import reaction

            out.append(reaction.certify_kernel(kx, kv, ka, p)[0])
        elif sample_time is None:
            out.append(continuous.certify_kernel(kx, kv, ka, p)[0])
        else:
            from . import sampled, sampled_reaction

            tp = float(leader_tau if i == 0 else vehicles[i - 1].params.tau)  # type: ignore[arg-type]
            kern = sampled_reaction.certify_kernel if p.reaction_delay > 0 else sampled.certify_kernel
            out.append(kern(kx, kv, ka, p, sample_time, tp)[0])
    return tuple(out)


def _reason(dec: StringDecision, j: int, vehicles: Sequence[Vehicle], certificates: Sequence[Any],
            x_to_omega: float) -> str:
    v = int(dec.verdict[j])
    loop = ("a pole on or outside the unit circle" if x_to_omega != 1.0
            else "a pole in the closed right half-plane")
    if dec.unstable[j] or not dec.stable[j]:
        bad = [f"{i} ({vv.name})" if vv.name else str(i)
               for i, (vv, c) in enumerate(zip(vehicles, certificates), start=1)
               if not (c.hurwitz if hasattr(c, "hurwitz") else c.schur)]
        which = ", ".join(bad) if bad else "?"
        if v == NOT_CERTIFIED:
            return f"vehicle {which} is not internally stable ({loop}): the string is not"
        return (f"vehicle {which} is within 10^-12 of the internal-stability boundary: "
                "undecided")
    if v == CERTIFIED:
        return ("every vehicle is internally stable and the product of |Γ_i| is at most 1 at "
                "every frequency (1 at ω = 0)")
    if v == NOT_CERTIFIED:
        w = float(dec.argmin[j]) / x_to_omega
        where = ("near ω = 0 (the product's low-frequency margin G(0) < 0)" if w == 0
                 else f"at ω = {w:.6g} rad/s (witness)")
        return f"the product of |Γ_i| exceeds 1 {where}"
    return ("neither proven within the budget: the product of |Γ_i| is within round-off of 1 "
            "somewhere (a tangency), or the refinement ran out")


def certify_string_kernel(
    vehicles: Sequence[Vehicle], *, sample_time: float | None = None,
    leader_tau: float | None = None, substrings: bool = True, n_grid: int | None = None,
    max_rounds: int = 30, max_intervals: int = 4096,
) -> StringCertificate:
    """The head-to-tail certificate of one string (module docstring).

    Inputs already checked by :func:`stringstab.certify.api.certify_string` (the way in):
    nothing is validated again here.

    Parameters
    ----------
    vehicles : sequence of Vehicle
        The followers, from the head (checked).
    sample_time : float, optional
        H (s) of the sampled-data loop; None for continuous time.
    leader_tau : float, optional
        The leader's lag τ_0 (sampled loop), s; None: the first follower's.
    substrings : bool
        Also certify every run of consecutive vehicles (for :attr:`StringCertificate.worst_substring`).
    n_grid : int, optional
        Initial intervals (default :func:`default_grid`).
    max_rounds, max_intervals : int
        Budget of the branch and bound, per string.

    Returns
    -------
    StringCertificate
    """
    vehicles = tuple(vehicles)
    N = len(vehicles)
    H = sample_time
    lt = None if H is None else float(vehicles[0].params.tau if leader_tau is None else leader_tau)
    certs = _vehicle_certificates(vehicles, H, lt)
    x_to_omega = 1.0 if H is None else float(H)

    def pred_tau(s: int) -> float:
        return float(vehicles[s - 1].params.tau if s else (lt or 0.0))

    runs: list[Substring] = []
    whole: tuple[StringDecision, int] | None = None
    lengths = range(2, N + 1) if substrings else (N,)
    for ell in lengths:
        starts = list(range(0, N - ell + 1)) if substrings else [0]
        if H is not None and vehicles[0].reaction_delay > 0:  # θ_r > 0: the cascade
            from .head_to_tail_reaction import decide_strings

            dec = decide_strings([vehicles[s:s + ell] for s in starts], H,
                                 [pred_tau(s) for s in starts],
                                 n_grid=n_grid or default_grid(ell), max_rounds=max_rounds,
                                 max_intervals=max_intervals)
        else:
            loop = _loop([vehicles[s:s + ell] for s in starts], H, [pred_tau(s) for s in starts])
            dec = decide(loop, n_grid=n_grid or default_grid(ell), max_rounds=max_rounds,
                         max_intervals=max_intervals)
        for j, s in enumerate(starts):
            runs.append(Substring(s + 1, s + ell, VERDICTS[int(dec.verdict[j])].value,
                                  float(dec.sup_gain[j]), float(dec.peak[j]) / x_to_omega))
        if ell == N:
            whole = (dec, 0)
    for i, c in enumerate(certs, start=1):
        runs.append(Substring(i, i, str(c.verdict), float(c.sup_gain), float(c.peak_omega)))
    assert whole is not None
    dec, j = whole
    v = int(dec.verdict[j])
    witness = (float(dec.argmin[j]) / x_to_omega
               if v == NOT_CERTIFIED and dec.stable[j] else math.nan)
    return StringCertificate(
        vehicles=vehicles, certificates=certs, verdict=VERDICTS[v].value,
        reason=_reason(dec, j, vehicles, certs, x_to_omega),
        sup_gain=float(dec.sup_gain[j]), peak_omega=float(dec.peak[j]) / x_to_omega,
        witness_omega=witness, omega_max=float(dec.right[j]) / x_to_omega,
        n_evals=int(dec.n_evals[j]), sample_time=H, leader_tau=lt,
        worst_substring=worst_substring(runs) if substrings else None,
        substrings=tuple(runs) if substrings else (),
    )


def worst_substring(runs: Sequence[Substring]) -> Substring | None:
    """The longest run proven to exceed 1 (ties: the larger sup), else the longest undecided one.

    Parameters
    ----------
    runs : sequence of Substring
        The runs examined.

    Returns
    -------
    Substring or None
        None when every run is certified.

    Examples
    --------
    >>> rs = [Substring(1, 1, "certified", 1.0, 0.0), Substring(2, 3, "not_certified", 1.2, 0.3),
    ...       Substring(1, 3, "inconclusive", 1.0, 0.0)]
    >>> worst_substring(rs).first, worst_substring(rs[:1])
    (2, None)
    """
    for verdict in (VERDICTS[NOT_CERTIFIED].value, VERDICTS[INCONCLUSIVE].value):
        cands = [r for r in runs if r.verdict == verdict]
        if cands:
            return max(cands, key=lambda r: (r.length, r.sup_gain if math.isfinite(r.sup_gain)
                                             else math.inf, -r.first))
    return None
