"""The certified points of a grid of gains: one helper for every caller.

Gain repairs start from, and fall back to, the points of a lattice over the gain box that the
certificate of their loop certifies (:mod:`stringstab.tuning.repair`'s lookup,
:mod:`stringstab.tuning.projection`'s certified maps, :mod:`stringstab.tuning.constraints`).
:func:`certified` decides which rows of an array of gains are certified for a loop — the
continuous loop at one τ, δ, T*, the sampled-data loop (``sample_time``) or every member of a
box of parameters — and :func:`certified_lattice` applies it to the lattice of
:func:`lattice`.  Cheap steps decide first, and only where they are sound:

* the continuous loop: the screen of :mod:`stringstab.certify.screen` (not Hurwitz, or
  |Γ(jω)| > 1 at a fixed frequency: a proof of failure) drops rows, then
  :func:`stringstab.certify.api.check` decides the rest;
* a box: a gain certified for every member is string stable at the box's centre, so the
  centre's screen (continuous loop) drops rows soundly; then the centre's point certificate
  (of the same loop, far cheaper than the robust one) picks the rows the robust certificate
  decides.  That step is sound only as far as the point certificate is never inconclusive
  where the robust one (with its looser bounds) certifies: not proven, never observed
  (``tests/certify/test_certify_grid.py`` compares with the robust certificate on every row);
* the sampled-data loop: its own sound screen (:class:`stringstab.certify.screen.SampledScreen`:
  g_H below its threshold at a fixed frequency, |H| > 1 there) drops rows, then its certificate
  decides the rest (the continuous screen says nothing about it), after the continuous
  certificate when both are asked for (``also_continuous``: the gains a sampled controller
  executes in the repair's training loop).

The region map (:func:`stringstab.regions.region_map`) reports every point's verdict,
sup |Γ| and margin rather than the certified points, so it runs the full certificate;
``tests/certify/test_certify_grid.py`` checks that it certifies exactly the points this helper returns.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError
from ..params import Box, Params
from ..params import sample_time as checked_sample_time
from .criteria import hurwitz_conditions
from .screen import sampled_screen, surely_uncertifiable
from .verdicts import Verdict

__all__ = ["certified", "certified_lattice", "lattice"]

Array = npt.NDArray[np.float64]


def lattice(lo: float, hi: float, n: int) -> Array:
    """The n³ points of the lattice over the gain box [lo, hi]³, k_x slowest, k_a fastest.

    Parameters
    ----------
    lo, hi : float
        The box of every gain (IDL Table 2: [−2, 2]).
    n : int
        Points per axis, ≥ 2 (``np.linspace(lo, hi, n)``).

    Returns
    -------
    ndarray, shape (n³, 3)
        Rows (k_x, k_v, k_a); row i·n² + j·n + k is (g[i], g[j], g[k]).

    Examples
    --------
    >>> lattice(0.0, 1.0, 2)[:3].tolist()
    [[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]]
    """
    if isinstance(n, bool) or int(n) != n or n < 2:
        raise StringStabError(f"a lattice has n >= 2 points per axis; got {n!r}")
    if not float(lo) < float(hi):
        raise StringStabError(f"a lattice needs lo < hi; got lo={lo!r}, hi={hi!r}")
    g = np.linspace(float(lo), float(hi), int(n))
    return np.stack(np.meshgrid(g, g, g, indexing="ij"), axis=-1).reshape(-1, 3)


def _check_certified(K: Array, params: Params | Box, sample_time: float | None,
                     heterogeneous: bool) -> npt.NDArray[np.bool_]:
    """The certificate of the loop (point or box, continuous or sampled) on every row of K.

    ``params`` is checked already (a :class:`Params` or :class:`Box`), so the loop is built
    from it directly (:class:`stringstab.certify.api.Loop`), not checked again per call.
    """
    from .api import Loop

    H = None if sample_time is None else checked_sample_time(sample_time)
    c = Loop(params, H, heterogeneous=heterogeneous).check(K[:, 0], K[:, 1], K[:, 2])
    return np.asarray(c.verdict == Verdict.CERTIFIED.value)


def certified(K: npt.ArrayLike, params: Params | Box, *, sample_time: float | None = None,
              heterogeneous: bool = True, also_continuous: bool = False
              ) -> npt.NDArray[np.bool_]:
    """Which rows of K the certificate of the loop certifies (string stable, IDL eq 10).

    Parameters
    ----------
    K : array_like, shape (n, 3)
        Gain triples (k_x [1/s²], k_v [1/s], k_a [-]) of IDL eq 4.
    params : Params or Box
        τ, δ, T* (s): one point, or a box every member of which must be certified
        (:mod:`stringstab.certify.robust`).
    sample_time : float, optional
        H (s): the sampled-data loop (zero-order hold, :mod:`stringstab.certify.sampled`).
    heterogeneous : bool
        Sampled box only: the predecessor's lag ranges over the τ box independently.
    also_continuous : bool
        With ``sample_time``: a row counts only if the continuous loop's certificate (at the
        same parameters) certifies it too.

    Returns
    -------
    ndarray of bool, shape (n,)
        True where certified: the rows whose :func:`stringstab.certify.api.check`
        verdict (of that loop, and of the continuous loop with ``also_continuous``) is
        ``"certified"`` — the cheap steps of the module docstring only skip rows that cannot
        be (for a box, see there).

    Examples
    --------
    >>> certified([[1.2, 0.5, 0.6], [0.9, -0.5, 1.1]], Params(0.1, 0.2, 1.1)).tolist()
    [True, False]
    """
    K = np.asarray(K, dtype=float).reshape(-1, 3)
    if not isinstance(params, (Params, Box)):
        raise StringStabError(f"params must be a Params or a Box; got {type(params).__name__}")
    ok = np.zeros(len(K), dtype=bool)
    if not len(K):
        return ok
    if sample_time is not None and also_continuous:
        idx = np.flatnonzero(certified(K, params, heterogeneous=heterogeneous))
        ok[idx] = certified(K[idx], params, sample_time=sample_time,
                            heterogeneous=heterogeneous)
        return ok
    point = params if isinstance(params, Params) else params.centre()
    if point.reaction_delay:
        # the screens are of the loop without reaction delay: with θ_r > 0 (issue 25) every row goes on
        cand = np.ones(len(K), bool)
    elif sample_time is None:
        cand = ~surely_uncertifiable(K, point)
    else:  # the sampled loop's own screen (at the centre of a box: a member)
        H = checked_sample_time(sample_time)
        cand = ~sampled_screen(point.tau, point.delta, point.headway, H).surely_uncertifiable(K)
    idx = np.flatnonzero(cand)
    if not isinstance(params, Params) and idx.size:
        idx = idx[_check_certified(K[idx], point, sample_time, heterogeneous)]
    if idx.size:
        ok[idx] = _check_certified(K[idx], params, sample_time, heterogeneous)
    return ok


def certified_lattice(lo: float, hi: float, n: int, params: Params | Box, *,
                      sample_time: float | None = None, heterogeneous: bool = True,
                      also_continuous: bool = False,
                      hurwitz_margin: float | None = None) -> Array:
    """The certified points of the lattice :func:`lattice` (lo, hi, n) for a loop.

    Parameters
    ----------
    lo, hi : float
        The box of every gain.
    n : int
        Points per axis.
    params : Params or Box
        τ, δ, T* (s), a point or a box (as for :func:`certified`).
    sample_time : float, optional
        H (s): the sampled-data loop.
    heterogeneous : bool
        Sampled box only: the predecessor's lag ranges over the τ box independently.
    also_continuous : bool
        With ``sample_time``: require the continuous certificate too.
    hurwitz_margin : float, optional
        Continuous loop at one point only: keep only the points whose Hurwitz conditions
        (:func:`stringstab.certify.criteria.hurwitz_conditions`) are ≥ this margin (starting
        points of a repair away from the stability boundary).  A restriction, not a screen.

    Returns
    -------
    ndarray, shape (m, 3)
        The certified points (rows k_x, k_v, k_a, in lattice order), read-only.

    Examples
    --------
    >>> pts = certified_lattice(-2.0, 2.0, 9, Params(0.1, 0.2, 1.1))
    >>> pts.shape[1], bool((pts[:, 0] > 0).all())
    (3, True)
    """
    K = lattice(lo, hi, n)
    if hurwitz_margin is not None:
        if not isinstance(params, Params) or sample_time is not None:
            raise StringStabError("hurwitz_margin restricts the continuous loop at one point; "
                                  f"got {type(params).__name__} with sample_time={sample_time!r}")
        conds = hurwitz_conditions(K[:, 0], K[:, 1], K[:, 2], tau=params.tau,
                                   headway=params.headway)
        K = K[np.all([c >= hurwitz_margin for c in conds], axis=0)]
    pts = np.ascontiguousarray(K[certified(K, params, sample_time=sample_time,
                                           heterogeneous=heterogeneous,
                                           also_continuous=also_continuous)])
    pts.setflags(write=False)
    return pts
