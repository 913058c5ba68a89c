"""Identify recorded vehicles and certify them: ``stringstab identify``.

* :mod:`~stringstab.identify.closed_loop` — one follower behind a measured predecessor (the
  simulator's exact ZOH lag, as a linear filter);
* :mod:`~stringstab.identify.fit` — closed-loop simulation-error fit, multi-start, bounds,
  identifiability notes;
* :mod:`~stringstab.identify.empirical` — the data's own transfer and amplifications;
* :mod:`~stringstab.identify.record` — a follower's record: single samples bridged, the
  stretches where it does not follow its predecessor excluded, clean segments;
* :mod:`~stringstab.identify.spacing` — the spacing policy (T*, l_0) from the quasi-steady parts;
* :mod:`~stringstab.identify.estimate` — one record's fit, certificate, bootstrap and profiles;
* :mod:`~stringstab.identify.wording` — verdicts and notes no more confident than the evidence;
* :mod:`~stringstab.identify.core` — :func:`identify`: every follower of one or more logs;
* :mod:`~stringstab.identify.report` — the table, ``identify.json``, CSV/Parquet and figures.

Readers of the logs: :func:`read_logs` (:func:`stringstab.io.platoon_logs.read_platoon_logs`
with the NGSIM pair parser of :mod:`stringstab.traffic`); :func:`example_log`: the two OpenACC
logs shipped in ``stringstab/data/openacc/``.
"""

from __future__ import annotations

from ..io.platoon_logs import PlatoonLog, Segment, clean_segments, read_platoon_logs
from .closed_loop import FollowerModel, simulate_follower
from .core import IdentifyResult, VehicleResult, identify
from .empirical import Empirical, empirical_transfer
from .fit import BOUNDS, PARAMETERS, FitResult, FollowerData, fit_follower
from .logs import EXAMPLES, example_log, read_logs
from .wording import statement

__all__ = [
    "BOUNDS",
    "EXAMPLES",
    "PARAMETERS",
    "Empirical",
    "FitResult",
    "FollowerData",
    "FollowerModel",
    "IdentifyResult",
    "PlatoonLog",
    "Segment",
    "VehicleResult",
    "clean_segments",
    "empirical_transfer",
    "example_log",
    "fit_follower",
    "identify",
    "read_logs",
    "read_platoon_logs",
    "simulate_follower",
    "statement",
]
