"""The certified lattice of the gain repair and its proven cells (IDL §3.3, the lookup).

The repair of training (:class:`stringstab.tuning.repair.GainRepair`, method ``"projection"``)
sends a proposal that is not certified to the nearest point of a *certified lattice*: the points
of a grid of spacing ``resolution`` over the gain box [lo, hi]³ that the exact certificates
certify (:func:`certified_lattice`, built once per process and parameter set, one vectorised
call of :func:`stringstab.certify.grid.certified_lattice`); the cells whose 8 corners are such
points are proven for every gain in them on demand (:func:`certified_cells`, a
:class:`~stringstab.certify.gain_cells.CertifiedCells`).  Both are cached per parameter set.

Moved here from ``stringstab.rl.repair`` (issue 32 item 3): the lattice is the tuning's idea.

References
----------
IDL paper, §3.3 "Parameter tuning method"; Table 2 (gain bounds [−2, 2]).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import numpy.typing as npt

from ..certify import grid
from ..certify.gain_cells import CertifiedCells
from ..errors import StringStabError
from ..params import Params

__all__ = ["certified_cells", "certified_lattice", "clear_caches"]

Array = npt.NDArray[np.float64]


def _key(tau: float, delta: float, headway: float, lo: float, hi: float, resolution: float,
         sample_time: float | None) -> tuple[float, float, float, float, float, float,
                                             float | None]:
    """The arguments as the caches' keys: floats, every one given (positionally or not).

    An ``lru_cache`` keys on the call's form, so ``f(..., None)`` and ``f(...)`` would be two
    entries, and the lattice (seconds of certificate calls) would be built twice.
    """
    return (float(tau), float(delta), float(headway), float(lo), float(hi), float(resolution),
            None if sample_time is None else float(sample_time))


def clear_caches() -> None:
    """Forget the cached lattices and cells (benchmarks that time their construction)."""
    _certified_lattice.cache_clear()
    _certified_cells.cache_clear()


def certified_lattice(tau: float, delta: float, headway: float, lo: float, hi: float,
                      resolution: float, sample_time: float | None = None,
                      reaction_delay: float = 0.0) -> Array:
    """The points of a grid of spacing ``resolution`` over [lo, hi]³ certified by ``check``.

    The points :func:`stringstab.certify.grid.certified_lattice` returns for this loop (with
    ``also_continuous``): the screen of :mod:`stringstab.certify.screen` first, then the exact
    certificate (:func:`stringstab.certify.api.check`) decides; with ``sample_time``,
    the sampled-data certificate at that step must certify the point too (checked on the
    points of the continuous lattice, itself cached: the same calls, row for row, as
    ``also_continuous``, and the repair's continuous cells reuse it).  The grid has
    round((hi − lo)/resolution) + 1 points per axis, so its spacing is ``resolution`` only
    when that divides hi − lo.  Cached (8 entries).

    Parameters
    ----------
    tau : float
        Actuator lag τ (IDL eq 7), s.
    delta : float
        Communication delay δ (eq 4), s.
    headway : float
        Time headway T* (eq 3), s.
    lo, hi : float
        The gain box [lo, hi] of every gain (Table 2: [−2, 2]).
    resolution : float
        Grid spacing.
    sample_time : float, optional
        Also require the sampled-data certificate of the zero-order-hold loop at this
        period H, s.
    reaction_delay : float
        θ_r, s (issue 25): with θ_r > 0, the points of the θ_r = 0 continuous lattice that the
        continuous certificate at θ_r certifies, and with ``sample_time`` of those the points
        the sampled-data certificate with θ_r at H certifies too
        (:class:`stringstab.certify.api.Loop` with ``reaction_delay`` and ``sample_time``,
        docs/sampled.md §10).  Every point is certified; a point certified only with θ_r is
        left out (conservative, never unsound).

    Returns
    -------
    ndarray (m, 3)
        Read-only; columns k_x, k_v, k_a.

    Raises
    ------
    StringStabError
        If no point of the lattice is certified.

    Examples
    --------
    >>> pts = certified_lattice(0.1, 0.2, 1.1, -2.0, 2.0, 0.5)
    >>> pts.shape[1], bool((pts[:, 0] > 0).all())
    (3, True)
    """
    return _certified_lattice(*_key(tau, delta, headway, lo, hi, resolution, sample_time),
                              float(reaction_delay))


@lru_cache(maxsize=8)
def _certified_lattice(tau: float, delta: float, headway: float, lo: float, hi: float,
                       resolution: float, sample_time: float | None,
                       reaction_delay: float) -> Array:
    """:func:`certified_lattice`, cached by its normalised arguments (:func:`_key`)."""
    n = round((hi - lo) / resolution) + 1
    if reaction_delay or sample_time is not None:
        # the points of a cached continuous lattice that the other certificate certifies too:
        # with H, the continuous lattice at θ_r (the repair's continuous cells reuse it at
        # θ_r = 0: the calls of grid.certified_lattice with also_continuous, row for row);
        # with θ_r alone, the lattice without θ_r
        base = certified_lattice(tau, delta, headway, lo, hi, resolution, None,
                                 reaction_delay if sample_time is not None else 0.0)
        keep = grid.certified(base, Params(tau, delta, headway, reaction_delay=reaction_delay),
                              sample_time=sample_time)
        pts = np.ascontiguousarray(base[keep])
        pts.setflags(write=False)
    else:
        pts = grid.certified_lattice(lo, hi, n, Params(tau, delta, headway))
    if not pts.shape[0]:
        extra = f", reaction_delay={reaction_delay:g}" if reaction_delay else ""
        raise StringStabError(
            f"no certified gains on the {n}^3 lattice over [{lo}, {hi}]^3 at tau={tau}, "
            f"delta={delta}, headway={headway}{extra}; expected parameters with a certified region")
    return pts


def certified_cells(tau: float, delta: float, headway: float, lo: float, hi: float,
                    resolution: float, sample_time: float | None = None) -> CertifiedCells:
    """The cells of the repair's lattice, proven on demand (:class:`~stringstab.certify.gain_cells.CertifiedCells`).

    The candidates are the cells whose 8 corners are points of :func:`certified_lattice`
    (both certificates, with ``sample_time``); a cell is proven for every gain in it the first
    time a gain falls in it or next to it.  Cached (8 entries, one object per parameter set,
    shared by the repairs of a process).

    Parameters
    ----------
    tau, delta, headway : float
        τ, δ, T* (s).
    lo, hi : float
        The gain box of every gain.
    resolution : float
        Lattice spacing (as for :func:`certified_lattice`).
    sample_time : float, optional
        Also the sampled-data certificate at this period H, s.

    Returns
    -------
    CertifiedCells
    """
    return _certified_cells(*_key(tau, delta, headway, lo, hi, resolution, sample_time))


@lru_cache(maxsize=8)
def _certified_cells(tau: float, delta: float, headway: float, lo: float, hi: float,
                     resolution: float, sample_time: float | None) -> CertifiedCells:
    """:func:`certified_cells`, cached by its normalised arguments (:func:`_key`)."""
    n = round((hi - lo) / resolution) + 1
    pts = certified_lattice(tau, delta, headway, lo, hi, resolution, sample_time)
    g = np.linspace(lo, hi, n)
    ijk = np.clip(np.searchsorted(g, pts, side="left"), 0, n - 1)
    on = np.zeros((n, n, n), dtype=bool)
    on[ijk[:, 0], ijk[:, 1], ijk[:, 2]] = np.all(g[ijk] == pts, axis=1)
    m = n - 1
    cand = np.ones((m, m, m), dtype=bool)
    for dx in (0, 1):
        for dy in (0, 1):
            for dz in (0, 1):
                cand &= on[dx:m + dx, dy:m + dy, dz:m + dz]
    return CertifiedCells(lo, hi, n, Params(tau, delta, headway), sample_time=sample_time,
                          candidates=cand)
