"""The recorded string's own head-to-tail amplification, from the log it was identified from.

The measured transfer from the first car's speed (the string's leader: the first follower's
predecessor) to the last follower's, by the Welch estimate of
:func:`stringstab.identify.empirical.empirical_transfer` — the same estimate, coherence
threshold, band and error as the per-follower transfer of ``stringstab identify`` — on the
stretches where *every* follower of the string is fully measured (the intersection of their
clean segments, of at least identify's shortest length), so the whole recorded string is
the one the certificate judges.  For a linear string it estimates ∏_i Γ_i(jω); its peak,
peak-to-peak and energy ratios set the data beside the certificate's sup ∏|Γ_i|.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import StringStabError, show
from ..identify.empirical import COHERENCE_MIN, OMEGA_MAX, Empirical, empirical_transfer
from ..io.platoon_logs import PlatoonLog, Segment, clean_segments
from .vehicles import RecordedString

__all__ = ["StringEmpirical", "common_segments", "string_empirical"]


@dataclass(frozen=True)
class StringEmpirical:
    """The data's head-to-tail amplification (module docstring).

    Attributes
    ----------
    empirical : Empirical
        The transfer, its peak (``gain``, ``gain_omega``, ``gain_error``, ``amplifies``), and
        the peak-to-peak and energy ratios.
    segments : list of Segment
        The stretches used.
    dt : float
        The log's step, s.
    log : PlatoonLog
        The log.
    """

    empirical: Empirical
    segments: list[Segment]
    dt: float
    log: PlatoonLog

    @property
    def coherence_min(self) -> float:
        """The coherence below which a frequency is noise (identify's threshold)."""
        return float(COHERENCE_MIN)

    @property
    def omega_max(self) -> float:
        """The highest frequency describing the cars, rad/s (identify's band)."""
        return float(OMEGA_MAX)

    def as_dict(self) -> dict[str, Any]:
        """The JSON form: the peak |Ĝ|, where, ± 2ε, the data's word, p2p, energy, seconds used.

        Returns
        -------
        dict
        """
        e = self.empirical

        def num(x: float) -> float | None:
            return float(x) if math.isfinite(x) else None

        return {"gain": num(e.gain), "omega": num(e.gain_omega),
                "gain_error": num(2 * e.gain_error * e.gain) if math.isfinite(e.gain) else None,
                "amplifies": e.amplifies, "peak_to_peak": num(e.peak_to_peak),
                "energy": num(e.energy),
                "seconds": float(sum(len(s) for s in self.segments) * self.dt)}


def common_segments(log: PlatoonLog, positions: Sequence[int], *,
                    min_duration: float) -> list[Segment]:
    """The runs where every follower of ``positions`` is fully measured (≥ ``min_duration``).

    Parameters
    ----------
    log : PlatoonLog
        The recorded platoon.
    positions : sequence of int
        The followers' recorded positions (each with its predecessor in the log).
    min_duration : float
        Shortest run kept, s.

    Returns
    -------
    list of Segment
    """
    ok = np.ones(log.t.size, dtype=bool)
    for p in positions:
        m = np.zeros(log.t.size, dtype=bool)
        for s in clean_segments(log, p, min_duration=0.0):
            m[s.start:s.stop] = True
        ok &= m
    edges = np.flatnonzero(np.diff(np.r_[0, ok.astype(np.int8), 0]))
    n_min = max(math.ceil(min_duration / log.dt - 1e-9), 2)
    return [Segment(int(a), int(b)) for a, b in zip(edges[::2], edges[1::2]) if b - a >= n_min]


def string_empirical(rec: RecordedString) -> StringEmpirical:
    """The recorded string's head-to-tail transfer and amplification (module docstring).

    Parameters
    ----------
    rec : RecordedString
        Read from an identify.json (its ``log``).

    Returns
    -------
    StringEmpirical

    Raises
    ------
    StringStabError
        When the string has no log (a CSV list), the log cannot be read, or no stretch has
        every follower measured.
    """
    from ..identify.logs import read_logs

    if rec.log is None:
        raise StringStabError(f"{rec.source} names no log (the data's own amplification needs "
                              "the identify.json of a recorded platoon)")
    if not Path(rec.log).is_file():
        raise StringStabError(f"the log {show(rec.log)} named in {rec.source} is not there (the "
                              "data's own amplification reads it)")
    logs = read_logs(rec.log, min_duration=rec.min_duration)
    if rec.platoon >= len(logs):
        raise StringStabError(f"the log {show(rec.log)} has {len(logs)} platoons; {rec.source} "
                              f"names platoon {rec.platoon}")
    log = logs[rec.platoon]
    first, last = rec.positions[0], rec.positions[-1]
    segs = common_segments(log, rec.positions, min_duration=rec.min_duration)
    if not segs:
        raise StringStabError(f"the log {show(rec.log)} has no stretch of {rec.min_duration:g} s "
                              f"with every follower {first}..{last} measured")
    v0 = log.speed[log.row(first - 1)]
    vN = log.speed[log.row(last)]
    return StringEmpirical(empirical_transfer(v0, vN, segs, log.dt), segs, log.dt, log)
