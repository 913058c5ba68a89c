r"""The string's attenuation margin μ on a scan, and its quadratic forms in one CAV's gains.

μ(K) = min_{ω>0} −ln(∏_i |Γ_i(jω)|²)(1 + ω²)/ω² (G(0)/∏ d_i(0) at ω = 0): the largest μ with
∏_i |Γ_i(jω)|² ≤ exp(−μω²/(1 + ω²)) at every ω (module docstring of
:mod:`stringstab.mixed.design`).  Evaluated on a dense grid (:func:`scan_grid`) from the parts
of the head-to-tail certificate (:meth:`stringstab.certify.head_to_tail.ContinuousString.parts`:
G by the telescoping sum and ∏ d_i), it is a *scan* for the design's search and for reporting —
it never certifies anything.  For one CAV, G(ω) and ∏ d_i(ω) are quadratic forms in its gains
(:func:`cav_forms`, by polarisation), which is what the design's NLP and the exclusion proof
(:mod:`stringstab.mixed.exclusion`) work on.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from ..certify.head_to_tail import ContinuousString, StringArrays, Vehicle, point_margin, square_sum
from ..certify.interval import Interval
from .cav import CavSpec, string_with_cavs

__all__ = ["attenuation_margin", "cav_forms", "margin_curve", "margins", "rate", "scan_grid",
           "terms"]

Array = npt.NDArray[np.float64]


def scan_grid(vehicles: Sequence[Vehicle]) -> Array:
    """The scan's frequencies: ω = 0 and 700 log-spaced up to well past every resonance.

    Parameters
    ----------
    vehicles : sequence of Vehicle
        The recorded string (its tail bound Ω sets the top: max(10, 3Ω) rad/s).

    Returns
    -------
    ndarray
        ω, rad/s, from 0 (then 10⁻³) upward.
    """
    loop = ContinuousString(StringArrays.of([list(vehicles)]))
    top = max(10.0, 3.0 * float(loop.right()[0]))
    return np.concatenate([[0.0], np.geomspace(1e-3, top, 700)])


def terms(strings: Sequence[Sequence[Vehicle]],
          omega: Array) -> tuple[Array, Array, Array, npt.NDArray[np.bool_]]:
    """G, its round-off bound, ∏ d_i and internal stability, per string (row) and ω (column).

    G is the telescoping margin of :mod:`stringstab.certify.head_to_tail` without the
    normalisation (every c_i = 1), so it is a quadratic form in any one vehicle's gains.

    Parameters
    ----------
    strings : sequence of sequence of Vehicle
        Strings of one length.
    omega : ndarray
        Frequencies, rad/s.

    Returns
    -------
    G, slack, D : ndarray, shape (len(strings), omega.size)
        G(ω), the bound on its round-off (:func:`stringstab.certify.head_to_tail.point_margin`)
        and ∏ d_i(ω) = ∏|D_i(jω)|².
    stable : ndarray of bool
        Every vehicle surely internally stable.
    """
    loop = ContinuousString(StringArrays.of([list(s) for s in strings]))
    n = len(strings)
    X = np.ascontiguousarray(np.broadcast_to(omega, (n, omega.size)))
    parts = loop.parts(np.arange(n), Interval(X))
    G, E, _ = point_margin(parts, np.ones((len(parts), 1, 1)))
    D: Array = np.ones(X.shape)
    for p in parts:
        D = D * square_sum(p.re_d, p.im_d)[0]
    stable, _ = loop.stability()
    return G, E, D, stable


def margin_curve(G: Array, D: Array, omega: Array) -> Array:
    """μ(ω) = −ln(∏|Γ_i|²)(1 + ω²)/ω² from G and ∏ d_i (∏|Γ_i|² = 1 − ω²G/∏d_i); G/∏d_i at 0.

    Parameters
    ----------
    G, D : ndarray
        G(ω) and ∏ d_i(ω) (rows: strings), from :func:`terms`.
    omega : ndarray
        Frequencies, rad/s.

    Returns
    -------
    ndarray
        μ(ω) (``inf`` where the product is 0).

    Examples
    --------
    >>> w = np.array([0.0, 1.0])
    >>> np.round(margin_curve(np.array([[2.0, 0.5]]), np.array([[4.0, 1.0]]), w), 6).tolist()
    [[0.5, 1.386294]]
    """
    w2 = omega * omega
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        x = w2 * G / D  # 1 − ∏|Γ_i|²
        mu = -np.log1p(-np.minimum(x, 1.0)) * (1.0 + w2) / np.where(w2 > 0, w2, 1.0)
        return np.asarray(np.where(w2 > 0, mu, G / D))


def margins(strings: Sequence[Sequence[Vehicle]], omega: Array) -> Array:
    """μ of each string on the grid ``omega`` (``-inf`` when a vehicle is not internally stable).

    Parameters
    ----------
    strings : sequence of sequence of Vehicle
        Strings of one length.
    omega : ndarray
        The grid, rad/s.

    Returns
    -------
    ndarray
        min over the grid of :func:`margin_curve`, per string.
    """
    G, _, D, stable = terms(strings, omega)
    mu = np.min(margin_curve(G, D, omega), axis=1)
    return np.asarray(np.where(stable & ~np.isnan(mu), mu, -np.inf))


def attenuation_margin(vehicles: Sequence[Vehicle], omega: Array | None = None) -> float:
    """μ of a string on a dense grid (module docstring): > 0 when the product stays below 1.

    A scan, for the design's search and for reporting; ``-inf`` when a vehicle is not
    internally stable.  It never certifies anything.

    Parameters
    ----------
    vehicles : sequence of Vehicle
        The string.
    omega : ndarray, optional
        The grid, rad/s (default :func:`scan_grid`).

    Returns
    -------
    float
        min over the grid of −ln(∏|Γ_i|²)(1 + ω²)/ω² (G(0)/∏ d_i(0) at ω = 0).
    """
    w = scan_grid(vehicles) if omega is None else np.asarray(omega, dtype=float)
    return float(margins([vehicles], w)[0])


def rate(mu: float, omega: Array) -> Array:
    """r(ω) with μ(ω) ≥ μ ⇔ G(ω) − r(ω) ∏d_i(ω) ≥ 0: r = (1 − e^{−μω²/(1+ω²)})/ω², r(0) = μ.

    Parameters
    ----------
    mu : float
        The margin level.
    omega : ndarray
        Frequencies, rad/s.

    Returns
    -------
    ndarray
        r(ω).
    """
    w2 = omega * omega
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.asarray(np.where(w2 > 0, -np.expm1(-mu * w2 / (1.0 + w2)) / np.where(w2 > 0, w2, 1.0),
                                   mu))


def cav_forms(vehicles: Sequence[Vehicle], pos: int, spec: CavSpec,
              omega: Array) -> tuple[Array, Array, Array]:
    """Quadratic forms in the CAV's gains of G(ω) and ∏ d_i(ω), and a bound on G's form error.

    G and ∏ d_i are linear in the CAV's n_c, d_c and g_c, each a quadratic polynomial of its
    gains (N_c and D_c are affine in them), so both are quadratic forms in K_c, recovered
    from ten evaluations by :func:`stringstab.tuning.constraints.quadratic_form` (in one pass,
    stacked side by side).  Each coefficient of G's form combines the ten values with weights
    of total magnitude ≤ 2, so it is within 2 max_p e_p of the exact one (e_p the round-off
    bound of the p-th value, :func:`terms`), plus the rounding of that combination (at most
    four operations: 8u max_p |G_p|, u = 2⁻⁵³).

    Parameters
    ----------
    vehicles : sequence of Vehicle
        The string (the vehicle at ``pos`` is replaced).
    pos : int
        The CAV's position, 1-based.
    spec : CavSpec
        The CAV.
    omega : ndarray
        Frequencies, rad/s (n of them).

    Returns
    -------
    fG, fD : ndarray, shape (10, n)
        The forms (c, b_x, b_v, b_a, A_xx, A_xv, A_xa, A_vv, A_va, A_aa) of G and ∏ d_i.
    err : ndarray, shape (n,)
        A bound on the error of each coefficient of G's form.
    """
    from ..tuning.constraints import quadratic_form

    n = omega.size
    slack: list[Array] = []

    def both(kx: Array, kv: Array, ka: Array) -> Array:
        strings = [string_with_cavs(vehicles, [pos], [(a, b, c)], spec)
                   for a, b, c in zip(kx, kv, ka)]
        G, E, D, _ = terms(strings, omega)
        slack.append(2.0 * np.max(E, axis=0) + 8.0 * 2.0 ** -53 * np.max(np.abs(G), axis=0))
        return np.concatenate([G, D], axis=1)

    F = quadratic_form(both)
    err = slack[0]
    return F[:, :n], F[:, n:], err
