"""Run the toolkit's controllers inside Eclipse SUMO (the optional extra ``sumo``, 1.28 series).

* :mod:`~stringstab.sumo.runtime` — start SUMO (libsumo, or TraCI on 127.0.0.1) with the
  ballistic update and the controller's step; refuse anything else;
* :mod:`~stringstab.sumo.scenario` — a straight one-lane road for a leader and N followers;
* :mod:`~stringstab.sumo.platoon` — :class:`SumoPlatoon` (the toolkit platoon's observe/advance
  contract, vehicles moved by SUMO) and :func:`cosimulate` → :class:`~stringstab.traffic.PlatoonResult`;
* :mod:`~stringstab.sumo.agreement` — the same case through the toolkit and through SUMO;
* :mod:`~stringstab.sumo.cacc` — SUMO's own CACC model: per-mode linear gains and certificates;
* :mod:`~stringstab.sumo.inscenario` — controlled vehicles inside an existing SUMO scenario.

SUMO is imported only when a simulation starts (:func:`~stringstab.sumo.runtime.import_api`),
so this package imports without the extra; running anything without it is a one-line error
naming the extra.
"""

from __future__ import annotations

from .agreement import TOLERANCE, agreement
from .inscenario import ScenarioRun, run_scenario
from .platoon import SumoPlatoon, ballistic_leader, cosimulate
from .runtime import EXTRA, SUMO_SERIES, SumoSession, check_config, import_api
from .scenario import straight_road

__all__ = [
    "EXTRA",
    "SUMO_SERIES",
    "TOLERANCE",
    "ScenarioRun",
    "SumoPlatoon",
    "SumoSession",
    "agreement",
    "ballistic_leader",
    "check_config",
    "cosimulate",
    "import_api",
    "run_scenario",
    "straight_road",
]
