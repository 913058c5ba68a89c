"""The reaction delay θ_r as a map axis: one region map per θ_r and the certified share vs θ_r.

:func:`reaction_sweep` evaluates :func:`stringstab.regions.region_map` on the same grid of
gains at each reaction delay θ_r of a list (issue 25: the command applied θ_r late,
τ a' = u(t − θ_r) − a) and returns a :class:`ReactionSweep`: the maps and the share of the grid
that the exact certificate certifies at each θ_r (:meth:`ReactionSweep.certified_shares`).
Each map is the one a single-θ_r call computes (the same function on the same grid), so the
share at each θ_r is that call's share.  At θ_r = 0 the map is the continuous map of today,
with every method asked for; at θ_r > 0 the one method is ``exact``
(:mod:`stringstab.certify.reaction`), so a sweep's maps evaluate ``exact`` alone.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from ..certify.verdicts import Verdict
from ..errors import StringStabError
from ..params import Box, check_reaction_delay, parameter_model
from .grid import region_map
from .report import percent
from .result import RegionMap

__all__ = ["ReactionSweep", "parse_reaction_delays", "reaction_sweep"]

Array = npt.NDArray[np.float64]

#: The most θ_r values one sweep takes (each is a whole map).
MAX_REACTION_DELAYS = 64


@dataclass(frozen=True, eq=False)
class ReactionSweep:
    """Region maps of one grid of gains at several reaction delays θ_r.

    Attributes
    ----------
    reaction_delays : ndarray
        θ_r (s), strictly increasing.
    maps : tuple of RegionMap
        The map at each θ_r (method ``exact``).
    """

    reaction_delays: Array
    maps: tuple[RegionMap, ...]

    def certified_shares(self) -> Array:
        """Share of the grid the exact certificate certifies at each θ_r.

        Returns
        -------
        ndarray
            In [0, 1], one per θ_r: ``verdict_shares()["exact"]["certified"]`` of each map.
        """
        return np.array([m.verdict_shares()["exact"][Verdict.CERTIFIED.value] for m in self.maps])

    def inconclusive_shares(self) -> Array:
        """Share of the grid where the exact certificate is inconclusive at each θ_r.

        Returns
        -------
        ndarray
            In [0, 1], one per θ_r.
        """
        return np.array([m.verdict_shares()["exact"][Verdict.INCONCLUSIVE.value] for m in self.maps])

    def rows(self) -> list[dict[str, Any]]:
        """The table of the sweep: θ_r, certified and inconclusive points and shares.

        Returns
        -------
        list of dict
            One per θ_r: ``reaction_delay`` (s), ``certified`` (points),
            ``certified_share``, ``inconclusive_share``, ``n`` (grid points).
        """
        out = []
        for th, m, s, i in zip(self.reaction_delays, self.maps, self.certified_shares(),
                               self.inconclusive_shares()):
            out.append({"reaction_delay": float(th), "certified": int(m.stable("exact").sum()),
                        "certified_share": float(s), "inconclusive_share": float(i),
                        "n": m.size})
        return out

    def summary(self) -> dict[str, Any]:
        """JSON-ready: the grid and loop of the first map, and :meth:`rows`.

        Returns
        -------
        dict
            ``params`` (τ, δ, T*), ``sample_time`` (H, of a sampled sweep only), ``axes``,
            ``fixed``, ``rows``.
        """
        meta = self.maps[0].metadata()
        H = {} if "sample_time" not in meta else {"sample_time": meta["sample_time"]}
        return {"params": {k: v for k, v in meta["params"].items() if k != "reaction_delay"},
                **H, "axes": meta["axes"], "fixed": meta["fixed"], "rows": self.rows()}

    def report(self) -> str:
        """Lines for people: each map's first line, then the table of the certified share.

        Returns
        -------
        str
            The report (no final newline).
        """
        lines = []
        for th, m in zip(self.reaction_delays, self.maps):
            lines.append(f"θ_r = {th:g} s: {m.report().splitlines()[1]}")
        lines.append("certified share vs θ_r:")
        lines.append(f"  {'θ_r [s]':>8}  {'certified':>10}  {'share':>8}  {'inconclusive':>12}")
        for r in self.rows():
            lines.append(f"  {r['reaction_delay']:>8g}  {r['certified']:>10,}  "
                         f"{percent(r['certified_share']):>8}  "
                         f"{percent(r['inconclusive_share']):>12}")
        return "\n".join(lines)


def parse_reaction_delays(text: str, what: str = "--reaction-delay") -> Array | None:
    """A list ``A,B,C`` or a range ``LO:HI:N`` of reaction delays θ_r; None for one value.

    One value (``0.2``) and an interval ``LO:HI`` (a box: the robust certificate's business)
    are not a sweep and return None, for the caller to pass on as they are.

    Parameters
    ----------
    text : str
        As given on the command line.
    what : str
        The option, for the messages.

    Returns
    -------
    ndarray or None
        θ_r (s), strictly increasing (a range's values rounded to 12 decimals), each checked by
        :func:`stringstab.params.check_reaction_delay` (finite, ≥ 0, ≤ 100 s); None when
        ``text`` is not a list or a range.

    Raises
    ------
    StringStabError
        A value that fails the check, fewer than 2 or more than 64 values, values not
        strictly increasing, or a range with N not an integer ≥ 2.

    Examples
    --------
    >>> parse_reaction_delays("0:0.3:4").tolist()
    [0.0, 0.1, 0.2, 0.3]
    >>> parse_reaction_delays("0,0.1,0.25").tolist()
    [0.0, 0.1, 0.25]
    >>> parse_reaction_delays("0.2") is None, parse_reaction_delays("0.1:0.3") is None
    (True, True)
    """
    s = str(text).strip()
    parts = s.split(":")
    if "," in s:
        values = [check_reaction_delay(v.strip(), f"{what} (reaction delay θ_r) value {v.strip()!r}")
                  for v in s.split(",")]
    elif len(parts) == 3:
        lo, hi = (check_reaction_delay(v.strip(), f"{what} (reaction delay θ_r) LO:HI:N bound")
                  for v in parts[:2])
        try:
            n = int(parts[2])
        except ValueError as e:
            raise StringStabError(f"{what} LO:HI:N must end with a count N (an integer >= 2); "
                                  f"got {text!r}") from e
        if n < 2 or not lo < hi:
            raise StringStabError(f"{what} LO:HI:N must have LO < HI and N >= 2; got {text!r}")
        # rounded to 12 decimals: 0:0.3:4 is 0, 0.1, 0.2, 0.3 exactly as the list 0,0.1,0.2,0.3
        values = np.round(np.linspace(lo, hi, n), 12).tolist()
    else:
        return None
    th = np.asarray(values, dtype=float)
    if not 2 <= th.size <= MAX_REACTION_DELAYS:
        raise StringStabError(f"{what} must list 2 to {MAX_REACTION_DELAYS} values for a map per "
                              f"θ_r; got {th.size}: {text!r}")
    if not np.all(np.diff(th) > 0):
        raise StringStabError(f"{what} values must be strictly increasing; got {text!r}")
    return th


def reaction_sweep(
    axes: Mapping[str, npt.ArrayLike],
    fixed: Mapping[str, float] | None = None,
    *,
    reaction_delays: Sequence[float] | npt.ArrayLike,
    tau: Any,
    delta: Any,
    headway: Any,
    sample_time: float | None = None,
    **options: Any,
) -> ReactionSweep:
    """The region map of the same grid at each reaction delay θ_r, and the certified share.

    Every θ_r is checked, and a loop no certificate answers refused (θ_r over a box with a
    sample time, θ_r beyond what the sampled lifting takes), before any map is computed.

    Parameters
    ----------
    axes, fixed
        The grid, as for :func:`stringstab.regions.region_map`.
    reaction_delays : sequence of float
        θ_r (s), at least 2, strictly increasing, each finite, ≥ 0 and ≤ 100 s.
    tau, delta, headway : float
        τ, δ, T* (s) of the continuous loop.
    sample_time : float, optional
        H (s): every map is the sampled one (at θ_r > 0 the sampled θ_r certificate,
        :mod:`stringstab.certify.sampled_reaction`; at θ_r = 0 the sampled certificate).
    **options
        Passed on to :func:`~stringstab.regions.region_map` (``workers``, ``block``,
        ``progress``, ``executor``); ``methods`` other than ``exact`` are refused (at θ_r > 0
        the Taylor criteria do not apply).

    Returns
    -------
    ReactionSweep
        The maps (method ``exact``) and their certified shares.

    Raises
    ------
    StringStabError
        Bad θ_r values, a loop no certificate answers, or methods other than ``exact``.

    Examples
    --------
    >>> import numpy as np
    >>> s = reaction_sweep({"k_x": np.linspace(0.2, 1.6, 5), "k_v": np.linspace(0.2, 1.6, 5)},
    ...                    {"k_a": 0.3}, reaction_delays=[0.0, 0.3], tau=0.1, delta=0.2,
    ...                    headway=1.1)
    >>> s.certified_shares().round(2).tolist()
    [0.92, 0.32]
    """
    th = np.asarray(reaction_delays, dtype=float).ravel()
    checked = (parse_reaction_delays(",".join(repr(float(v)) for v in th), "reaction_delays")
               if th.size > 1 else None)
    if checked is None:
        raise StringStabError(f"reaction_delays must list 2 to {MAX_REACTION_DELAYS} values; "
                              f"got {th.tolist()}")
    methods = options.pop("methods", None)
    if methods not in (None, "exact", ("exact",), ["exact"]):
        raise StringStabError("a map per reaction delay θ_r evaluates 'exact' (the Taylor criteria "
                              f"are of the loop without θ_r); got methods {methods!r}")
    from ..certify.api import Loop

    for v in checked:  # the refusal (sampled, box) before any work
        if v > 0:
            Loop(parameter_model(tau, delta, headway, v), sample_time)
    if isinstance(parameter_model(tau, delta, headway), Box):  # pragma: no cover - refused above
        raise StringStabError("a map per reaction delay θ_r needs one τ, δ, T*")
    maps = tuple(region_map(axes, fixed, tau=tau, delta=delta, headway=headway,
                            sample_time=sample_time, methods="exact", reaction_delay=float(v),
                            **options) for v in checked)
    return ReactionSweep(checked, maps)
