"""The model's parameters τ, δ, T*, θ_r, checked: at a point and over a box.

* :mod:`~stringstab.params.points` — :class:`Params` (every value a point; IDL paper eqs 3-9
  and θ_r of issue 25), the checks of one value (:func:`positive`, :func:`finite`,
  :func:`count`, :func:`check_params`, :func:`check_reaction_delay`, :func:`sample_time`) and
  of the gains (:func:`as_gains`), the defaults of the IDL paper's Table 2;
* :mod:`~stringstab.params.intervals` — intervals (:func:`parse_interval`,
  :func:`as_interval`), the :class:`Box` they form (:func:`check_box`), and
  :func:`parameter_model`, which turns what a caller gives into a :class:`Params` or a
  :class:`Box`.

Every name is importable from here (``from stringstab.params import Box, Params``), as it was
when this was one module.
"""

from .intervals import Box, Interval, as_interval, check_box, parameter_model, parse_interval
from .points import (
    DEFAULT_DELTA,
    DEFAULT_HEADWAY,
    DEFAULT_TAU,
    Params,
    as_gains,
    check_params,
    check_reaction_delay,
    count,
    finite,
    positive,
    sample_time,
)

__all__ = [
    "DEFAULT_DELTA",
    "DEFAULT_HEADWAY",
    "DEFAULT_TAU",
    "Box",
    "Interval",
    "Params",
    "as_gains",
    "as_interval",
    "check_box",
    "check_params",
    "check_reaction_delay",
    "count",
    "finite",
    "parameter_model",
    "parse_interval",
    "positive",
    "sample_time",
]
