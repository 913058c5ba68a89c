"""Repairing gains that are not string stable: region growing and a nearest-point projection.

In the IDL strategy every action K = [k_x, k_v, k_a] proposed by the agent goes
through a *parameter tuning* step that replaces gains that are not string
stable by nearby gains that are (IDL paper §3.3).  Two methods are offered;
both report whether their output is certified by the exact certificate
(:func:`stringstab.certify.api.certify`, or its verdict-only form
:func:`stringstab.certify.api.check`: the same sound decision), never by a
Taylor formula alone.

:func:`region_growing`
    The paper's region-growing grid search (§3.3, Steps 1-6) as written: its
    candidate test is the Taylor Proposition 1 (types I-IV), so its output may
    fail the exact certificate.  Choices made where the paper is silent are
    listed in the function's docstring and in ``docs/tuning.md``.
:func:`project` (and the stateful :class:`Projector` for a control loop)
    The certified gains nearest to K0 in a weighted Euclidean distance, solved
    with CasADi/IPOPT under the internal-stability conditions with a margin
    and the exact frequency condition g(ω_j) ≥ ε on a finite set of
    frequencies, refined by exchange until the exact certificate certifies;
    first, a Newton predictor on the KKT system of a small active set
    (usually one constraint) answers without IPOPT when the exact
    certificate certifies its point.

:class:`GainRepair` (:mod:`~stringstab.tuning.repair`)
    The repair of a training loop (IDL §3.3 at every control step): a certified lookup on a
    lattice of certified gains and its proven cells (:mod:`~stringstab.tuning.lattice`), or one
    of the two methods above per uncertified triple; every executed triple is certified by the
    exact certificates.  :func:`stringstab.rl.repair.repair_for` rebuilds it from a training
    config or a saved policy.

:func:`project` and :func:`region_growing` return a :class:`TuneResult` (:class:`TuneResults` for many, owning their
records, columns and summary).  Gains that the exact certificate already
certifies are returned unchanged, without any search or solve.

Modules: :mod:`~stringstab.tuning.result` (the result types),
:mod:`~stringstab.tuning.inputs` (input checks),
:mod:`~stringstab.tuning.region_growing`, :mod:`~stringstab.tuning.projection`
(:func:`project`), :mod:`~stringstab.tuning.projector` (the :class:`Projector`),
:mod:`~stringstab.tuning.nlp` (the CasADi/IPOPT problems), :mod:`~stringstab.tuning.exchange`
(the exchange method), :mod:`~stringstab.tuning.predictor` (the Newton predictor),
:mod:`~stringstab.tuning.margin_terms` (the margin's gradient, Newton terms and CasADi form),
:mod:`~stringstab.tuning.methods` (:func:`tune`), :mod:`~stringstab.tuning.repair` and
:mod:`~stringstab.tuning.lattice` (the repair of training); the figure
:func:`~stringstab.plots.plot_moves` lives in :mod:`stringstab.plots.tuning` (the
plots import the tuning, never the reverse).

References
----------
IDL paper, §3.3 "Parameter tuning method" (types I-IV, eqs 25-26, Steps 1-6);
Table 2 (gain bounds [-2, 2]).
R. Hettich, K. O. Kortanek, "Semi-infinite programming: theory, methods, and
applications", SIAM Review 35 (1993) 380-429 (the exchange method).
"""

from __future__ import annotations

from .methods import METHODS, tune
from .projection import project
from .projector import Projector
from .region_growing import region_growing
from .repair import REPAIR_METHODS, GainRepair
from .result import TuneResult, TuneResults

__all__ = [
    "METHODS",
    "REPAIR_METHODS",
    "GainRepair",
    "Projector",
    "TuneResult",
    "TuneResults",
    "project",
    "region_growing",
    "tune",
]
