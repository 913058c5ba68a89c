"""Stability-region maps: verdicts of every method on a grid of gains K = [k_x, k_v, k_a].

:func:`region_map` evaluates a grid over two gains (the third fixed) or over
all three, and returns a :class:`RegionMap` holding, per grid point,

* ``hurwitz``: internal stability of Γ (k_x > 0 and k_v + (T* − τ)k_x > 0,
  :func:`stringstab.certify.criteria.hurwitz`);
* ``type``: the stability type I-IV of IDL §3.3 from the *derived* Ψ2, Ψ3, Λ
  (:func:`stringstab.certify.criteria.stability_type`), and ``type_printed`` from the
  Ψ as printed (IDL eqs 13-15) when the ``printed`` method is requested;
* ``verdict[method]`` for each requested method:

  ``exact``
      the sound certificate with the exact delay
      (:func:`stringstab.certify.api.certify_batch`): ``certified``,
      ``not_certified`` or ``inconclusive``;
  ``taylor``
      Proposition 1 (IDL eqs 12-15) with the *derived* Ψ and the corrected
      logic, **and** Hurwitz: ``stable`` or ``unstable``;
  ``printed``
      Proposition 1 with the Ψ and the logic *as printed*, **and** Hurwitz.

  Proposition 1 alone does not check internal stability (the printed logic
  ``(Ψ1, Ψ2, Ψ3 ≥ 0) ∨ Λ ≤ 0`` accepts gains with k_x < 0), so a map's Taylor
  verdicts require Hurwitz as well, like the exact one; the bare Proposition-1
  booleans are kept in ``prop1[method]``;
* ``sup_gain`` (‖Γ‖_{H∞} = sup_ω |Γ(jω)|, ``inf`` when Γ is not internally
  stable) and ``margin`` (min_ω g(ω) found) when ``exact`` is requested.

With ``sample_time`` or an interval for τ, δ or T*, ``exact`` is the sampled-data
(:mod:`stringstab.certify.sampled`) or robust (:mod:`stringstab.certify.robust`) certificate, ``hurwitz`` the
stability of that loop (Schur; every member of the box), and the one other method is
``continuous`` (sampled maps only): the continuous-time certificate at the same parameters,
so that :func:`stringstab.plots.plot_comparison` draws the band of gains certified in
continuous time but not when sampled.  The Taylor criteria are of the continuous loop at one
τ, δ, T* and are not evaluated there (``type`` is None).

Classes of the class maps (:meth:`RegionMap.classes`):

* ``taylor`` / ``printed``: *not internally stable*, then the type of that
  method's Ψ: *type III* (Ψ3 < 0), *type IV* (Ψ3 ≥ 0, Ψ2 < 0, Λ > 0),
  *type I* (Ψ2, Ψ3 ≥ 0), *type II* (Ψ3 ≥ 0, Ψ2 < 0, Λ ≤ 0);
* ``exact``: *not internally stable* (‖Γ‖∞ = ∞), *not certified* (internally
  stable, some |Γ(jω)| > 1), *inconclusive*, *certified* (‖Γ‖∞ ≤ 1).

The types are defined from Ψ2, Ψ3, Λ only: a type I or II point with Ψ1 < 0
fails the derived Proposition 1, and the printed logic can accept a type III
point with Λ ≤ 0.  The class map shows the types; the verdicts are in
``verdict``.

Modules: :mod:`~stringstab.regions.grid` (the grid, its blocks, :func:`region_map`),
:mod:`~stringstab.regions.pool` (worker processes), :mod:`~stringstab.regions.codes` (the
names and codes: gains, methods, verdict labels, classes), :mod:`~stringstab.regions.result`
(:class:`RegionMap`: classes, shares, summary, slices), :mod:`~stringstab.regions.storage`
(the map's files: metadata, columns, NPZ and CSV writers, the reader),
:mod:`~stringstab.regions.files` (the NPZ and CSV formats), :mod:`~stringstab.regions.report` (the text report) and
:mod:`~stringstab.regions.reaction_sweep` (:func:`reaction_sweep`: a map per reaction delay
θ_r and the certified share vs θ_r, issue 25).

Evaluation is chunked in blocks of grid points (memory bounded by the block
size, not the grid) and spread over worker processes.  The Taylor quantities
are evaluated as polynomials in one gain with coefficients on the plane of the
other two (Horner's rule, coefficients generated from the SymPy expressions of
:func:`stringstab.derive.symbolic.derived_psi` and :func:`stringstab.derive.printed.printed_psi`);
this agrees with :func:`stringstab.certify.criteria.taylor_criteria` to round-off
(~1e-15 relative), so only grid points lying exactly on a boundary Ψ = 0 or
Λ = 0 can fall on the other side of it.

References
----------
IDL paper, Proposition 1 (eqs 12-15), §3.3 (types I-IV), Definition 1 (eq 10).
"""

from __future__ import annotations

from .codes import CONTINUOUS, EXACT_CLASSES, GAIN_NAMES, METHODS, TYPE_CLASSES, VERDICT_LABELS
from .grid import EXACT_BLOCK, TAYLOR_BLOCK, region_map
from .reaction_sweep import ReactionSweep, reaction_sweep
from .result import RegionMap, describe_params, load_npz

__all__ = [
    "CONTINUOUS",
    "EXACT_BLOCK",
    "EXACT_CLASSES",
    "GAIN_NAMES",
    "METHODS",
    "TAYLOR_BLOCK",
    "TYPE_CLASSES",
    "VERDICT_LABELS",
    "ReactionSweep",
    "RegionMap",
    "describe_params",
    "load_npz",
    "reaction_sweep",
    "region_map",
]
