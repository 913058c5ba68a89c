"""The nearest certified gains: :func:`project`, a CasADi/IPOPT projection refined by exchange.

:func:`project` (and the stateful :class:`Projector`, for a control loop) solves
min ‖K − K0‖_W subject to the internal-stability conditions with a margin and the exact
frequency condition g(ω_j; K) ≥ ε on a finite set of frequencies, refined by exchange until
the exact certificate (:func:`stringstab.certify.api.check`) certifies; first, the Newton
predictor of :mod:`stringstab.tuning.predictor` answers without IPOPT when it can.  The NLP's
constraints are the generated Hurwitz conditions (:func:`stringstab.certify.criteria.hurwitz_conditions`)
and g (:func:`stringstab.tuning.margin_terms.casadi_g`).

For the sampled-data loop (``sample_time``) and for a box of parameters (intervals: every
member certified) the same exchange runs on the NLP of
:func:`~stringstab.tuning.nlp.quadratic_nlp`, whose constraints
are quadratic forms in K taken at members and frequencies of that loop
(:mod:`stringstab.tuning.constraints`: the sampled margin g_H(θ), the Schur conditions, g(ω)
at a member of the box), the certificate of that loop deciding every output and supplying
each new constraint (its witness member and frequency).

The pieces live apart: the NLPs in :mod:`~stringstab.tuning.nlp`, the exchange in
:mod:`~stringstab.tuning.exchange`, the stateful :class:`~stringstab.tuning.Projector` in
:mod:`~stringstab.tuning.projector`; this module is the stateless way in.

References
----------
R. Hettich, K. O. Kortanek, "Semi-infinite programming: theory, methods, and
applications", SIAM Review 35 (1993) 380-429 (the exchange method).
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import lru_cache
from typing import Any

import numpy as np
import numpy.typing as npt

from ..constants import GAIN_BOUNDS
from ..params import Box, Params, parameter_model, positive
from ..params import sample_time as _sample_time
from .inputs import as_bounds, as_weights
from .projector import Projector
from .result import TuneResult

__all__ = ["project"]

Array = npt.NDArray[np.float64]


@lru_cache(maxsize=64)
def _default_projector(params: Params | Box, weights: tuple[float, ...],
                       bounds: tuple[float, float], hurwitz_margin: float, eps: float,
                       max_exchange: int, predictor: bool = True,
                       sample_time: float | None = None, heterogeneous: bool = True) -> Projector:
    return Projector(tau=params.tau, delta=params.delta, headway=params.headway,
                     sample_time=sample_time, heterogeneous=heterogeneous, weights=weights,
                     bounds=bounds, hurwitz_margin=hurwitz_margin, eps=eps,
                     max_exchange=max_exchange, cache_size=0, predictor=predictor,
                     reaction_delay=params.reaction_delay)


def project(
    K0: Sequence[float] | Array,
    *,
    tau: Any,
    delta: Any,
    headway: Any,
    sample_time: float | None = None,
    heterogeneous: bool = True,
    weights: Sequence[float] = (1.0, 1.0, 1.0),
    bounds: tuple[float, float] = GAIN_BOUNDS,
    hurwitz_margin: float = 1e-3,
    eps: float = 1e-4,
    warm_start: Sequence[float] | None = None,
    max_exchange: int = 25,
    predictor: bool = True,
    reaction_delay: Any = 0.0,
) -> TuneResult:
    r"""The certified gains nearest to K0: min ‖K − K0‖_W subject to string stability.

    Solves, with CasADi and IPOPT,

    .. math::
        \min_K \sum_i w_i (K_i - K_{0,i})^2 \quad\text{s.t.}\quad
        k_x \ge m,\; k_v + (T^* - τ)k_x \ge m,\;
        g(ω_j; K) \ge ε \;(j = 1..n),\; K \in [\text{lo}, \text{hi}]^3,

    where g(ω) = (|D(jω)|² − |N(jω)|²)/ω² (:func:`stringstab.certify.frequency.margin_g`;
    g(0) = Ψ3), so g(ω_j) ≥ ε is |D(jω_j)|² − |N(jω_j)|² ≥ ε ω_j².  The frequency
    set starts as {0}, a fixed ladder of 16 frequencies (0.2 to 5 rad/s,
    geometric), the violating local minima of g(·; K0) (each also at 0.95
    and 0.9 times itself) and, for each of them, the predicted dip of the
    repaired gains (the dip of g at the nearest point of the linearised
    constraint, followed twice; each also at 0.98 and 1.02 times itself).  It
    is refined by *exchange*: after each solve the exact certificate
    (:func:`stringstab.certify.api.check`) is asked; if it does not certify
    K, its witness frequency (where |Γ(jω)| > 1) and the local minima of
    g(·; K) below 0 found by a dense scan are added, each with neighbours at
    ±5 %.  The loop ends when the certificate certifies K, when nothing new
    can be added, or after ``max_exchange`` solves.

    The first solve starts from the nearest point (weighted distance) of a
    precomputed map of certified gains (a 21³ grid over the bounds, certified
    once per process and parameter set), or from ``warm_start``.  Since the
    problem is not convex, IPOPT finds a local solution; if that map point is
    nearer than the local solution (or the exchange fails), the map point,
    which is certified, is returned instead, so the result is never further
    than the nearest certified grid point.

    The NLP is built once per process for each frequency-slot capacity
    (4, 6, ..., 16, 20, ..., 32, 40, 48; each on first use), with K0, the
    weights, τ, δ, T* and the frequencies as parameters; the smallest that
    fits is used and unused slots are disabled by a lower bound of −∞.

    Before any IPOPT solve, a *predictor* (``predictor=True``) solves the
    problem by Newton's method on its KKT system with a small active set:
    it starts with the constraint most violated at K0 relative to its
    gradient (a margin, a bound, Ψ3 = g(0) ≥ ε, or g ≥ ε at a predicted dip,
    the dip's frequency being a variable with ∂g/∂ω = 0, so that g ≥ ε holds
    at the dip itself), adds after each solve the constraint then most
    violated (at most three), and drops one whose multiplier turns negative.
    Its point is returned when every multiplier is positive, every
    constraint of the first NLP holds (the margins, the bounds, g ≥ ε on its
    frequency set) and the exact certificate certifies it; otherwise the
    IPOPT path above runs unchanged (and the map fallback applies to both).

    For the sampled-data loop and for a parameter box there is no predictor; the exchange
    runs on an NLP whose constraints are quadratic forms in K
    (:mod:`stringstab.tuning.constraints`): the Schur (or worst-corner Hurwitz) conditions,
    the margin at 0 at the box's corners and on the ladder at its centre, and then, after
    each solve, the margin at the certificate's witness member and frequency (θ when
    sampled) and at the dips of that member's margin; the certificate of that loop decides
    every output, and the fallback is the nearest point of that loop's certified map.

    Parameters
    ----------
    K0 : sequence of 3 floats
        The gains to repair.
    tau, delta, headway : float, (lo, hi) or "LO:HI"
        Model parameters (s); an interval asks for gains certified for every member of the
        box (the robust certificate, :mod:`stringstab.certify.robust`).
    sample_time : float, optional
        H (s): gains certified for the sampled-data loop (:mod:`stringstab.certify.sampled`).
    heterogeneous : bool
        Sampled box only: the predecessor's lag ranges over the τ box independently.
    weights : sequence of 3 floats
        Weights of the squared distance, > 0.
    bounds : (float, float)
        Bounds on every gain (IDL Table 2: [-2, 2]).
    hurwitz_margin : float
        m in k_x ≥ m and k_v + (T* − τ)k_x ≥ m (internal stability with a margin); sampled,
        m in each Schur condition normalised to these as H → 0
        (:func:`stringstab.certify.schur.schur_margins`).
    eps : float
        ε > 0 of the frequency constraints.
    warm_start : sequence of 3 floats, optional
        Starting point of the first solve instead of the certified map.
    max_exchange : int
        Maximum number of solves.
    predictor : bool
        Try the Newton predictor before IPOPT (default); False: IPOPT only.
    reaction_delay : float
        θ_r ≥ 0 (s), the reaction delay on the whole command (issue 25; at one τ, δ, T*,
        continuous or with ``sample_time``): the margin is g_θ
        (:mod:`stringstab.certify.margin_reaction`) or, sampled, g_{H,θ_r}
        (:mod:`stringstab.tuning.sampled_reaction_margin`), taken as quadratic forms in K as
        for the sampled loop, with k_x ≥ ``hurwitz_margin``; the certificate with θ_r
        (:mod:`stringstab.certify.reaction`, :mod:`stringstab.certify.sampled_reaction`)
        decides every output.

    Returns
    -------
    TuneResult
        ``certified`` is the exact certificate's verdict on the output (of the loop asked for).

    Raises
    ------
    StringStabError
        On non-finite gains, parameters out of range or bad options.

    See Also
    --------
    Projector : the same with a cache and warm starts for a control loop.

    Examples
    --------
    >>> r = project([0.9, -0.5, 1.1], tau=0.1, delta=0.2, headway=1.1)
    >>> r.status, r.certified, round(r.distance, 3)
    ('repaired', True, 0.033)
    >>> project([1.3, 0.0, 0.6], tau=0.1, delta=0.2, headway=1.1).status
    'unchanged'
    >>> r = project([0.9, -0.5, 1.1], tau=0.1, delta=0.2, headway=1.1, sample_time=0.1)
    >>> r.status, r.certified
    ('repaired', True)
    """
    proj = _default_projector(
        parameter_model(tau, delta, headway, reaction_delay), tuple(float(v) for v in as_weights(weights)),
        as_bounds(bounds), positive("hurwitz_margin", hurwitz_margin, allow_zero=True),
        positive("eps", eps), max_exchange, bool(predictor),
        None if sample_time is None else _sample_time(sample_time), bool(heterogeneous),
    )
    return proj(K0, warm_start=warm_start, use_state=False)

