"""Mixed platoons: recorded strings of cars, head-to-tail verdicts, and the CAV that stops the wave.

* :mod:`~stringstab.mixed.vehicles` — a string of followers read from ``identify.json`` (the
  vehicles identified from a log, in recorded order) or from a CSV list of parameters;
* :mod:`~stringstab.mixed.empirical` — the recorded string's own head-to-tail amplification
  (the measured transfer from the first car's speed to the last car's);
* :mod:`~stringstab.mixed.design` — gains of one or more CAVs put in place of recorded
  followers so that the whole string is certified head to tail
  (:func:`stringstab.certify.api.certify_string`, the final judge), or the best sup found;
* :mod:`~stringstab.mixed.replay` — the recorded leader replayed through the identified
  vehicles, with and without the CAV(s), in the toolkit's simulator (m_p along the string).

The command line is ``stringstab platoon`` (:mod:`stringstab.cli.platoon`); the figures are in
:mod:`stringstab.plots.mixed` and the report in :mod:`stringstab.report.mixed`.
"""

from __future__ import annotations

from .vehicles import RecordedString, read_vehicles

__all__ = ["RecordedString", "read_vehicles"]
