r"""A proof that no gains of one CAV at a position certify the string: a branch and bound in K.

If the string with a CAV of gains K is certified, the CAV is internally stable — k_x > 0 (else
D(0) = k_x ≤ 0 and D(s) → ∞ as s → +∞ put a real root in s ≥ 0) and, without a reaction delay,
k_v + (T* − τ)k_x > 0 (its other Hurwitz condition) — and G(ω; K) ≥ 0 at every ω ≥ 0 (the
telescoping margin of :mod:`stringstab.certify.head_to_tail`, continuous at 0).  So a box of
gains in which every K violates one of these at one of finitely many frequencies ω_j holds
no certifiable K.  For one CAV, G(ω_j; K) is a quadratic form q_j(K) in its gains
(:func:`stringstab.mixed.attenuation.cav_forms`), known to within 2e_j per coefficient, hence
within 2e_j (1 + 3B + 9B²) at any K with |K_i| ≤ B.  At ω = 0 every term of
G(0) = Σ_k Ψ3_k ∏_{i≠k} k_{x,i}² carries the CAV's k_x (Ψ3 = k_x(T*²k_x + 2T*k_v − 2 + 2k_a)),
so G(0)/k_x is the *linear* form b_x + A_xx k_x + 2A_xv k_v + 2A_xa k_a of q_0's coefficients,
and for k_x > 0 its sign is G(0)'s: used instead of q_0, it does not vanish with k_x (q_0 does,
and could never exclude the boxes along k_x = 0).  On a box, an upper bound of q_j is the sum
of each term's maximum over the box (the natural interval extension, widened by a relative
10⁻¹² for its own rounding); a box is **excluded** when some upper bound is below minus that
error, or when a Hurwitz condition's maximum is ≤ 0.  Boxes that are not are split in two
along their widest side (relative to the bounds), all at once, until every box is excluded —
the proof — or the budget is spent, in which case nothing is claimed.

References
----------
R. E. Moore, R. B. Kearfott, M. J. Cloud, *Introduction to Interval Analysis*, SIAM (2009),
§6 (interval extensions) and §12 (branch and bound).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ..certify.head_to_tail import Vehicle
from .attenuation import cav_forms
from .cav import CavSpec

__all__ = ["Exclusion", "exclusion_frequencies", "prove_no_cav", "quadratic_upper"]

Array = npt.NDArray[np.float64]


@dataclass(frozen=True)
class Exclusion:
    """The outcome of :func:`prove_no_cav`.

    Attributes
    ----------
    proven : bool
        Every box excluded: no gains within the bounds (:meth:`CavSpec.lower`,
        :meth:`CavSpec.upper`: k_x ≥ ``min_kx``) certify the string with this CAV.
    boxes : int
        Boxes examined.
    remaining : int
        Boxes not excluded when the budget ran out (0 when proven).
    frequencies : int
        Frequencies ω_j used.
    """

    proven: bool
    boxes: int
    remaining: int
    frequencies: int


def exclusion_frequencies(top: float = 5.0, n: int = 64) -> Array:
    """ω = 0 and ``n`` log-spaced frequencies on [10⁻³, top] rad/s.

    Parameters
    ----------
    top : float
        The highest frequency, rad/s.
    n : int
        How many positive frequencies.

    Returns
    -------
    ndarray
    """
    return np.concatenate([[0.0], np.geomspace(1e-3, top, n)])


def quadratic_upper(forms: Array, lo: Array, hi: Array) -> Array:
    """An upper bound of each quadratic form over each box (the natural interval extension).

    Parameters
    ----------
    forms : ndarray, shape (m, 10)
        (c, b_x, b_v, b_a, A_xx, A_xv, A_xa, A_vv, A_va, A_aa) per form, q = c + bᵀK + KᵀAK.
    lo, hi : ndarray, shape (n, 3)
        The boxes.

    Returns
    -------
    ndarray, shape (n, m)
        ≥ max over the box of each form (up to the rounding of this sum, covered by the
        caller's slack).

    Examples
    --------
    >>> f = np.array([[1.0, 0, 0, 0, -1.0, 0, 0, 0, 0, 0]])  # 1 − k_x²
    >>> quadratic_upper(f, np.array([[2.0, 0, 0]]), np.array([[3.0, 1, 1]])).tolist()
    [[-3.0]]
    """
    up = np.zeros((lo.shape[0], forms.shape[0])) + forms[:, 0][None, :]
    for i in range(3):
        b = forms[:, 1 + i][None, :]
        up += np.maximum(b * lo[:, i:i + 1], b * hi[:, i:i + 1])
    sq_lo = np.where((lo <= 0) & (hi >= 0), 0.0, np.minimum(lo * lo, hi * hi))
    sq_hi = np.maximum(lo * lo, hi * hi)
    for i, col in ((0, 4), (1, 7), (2, 9)):
        a = forms[:, col][None, :]
        up += np.maximum(a * sq_lo[:, i:i + 1], a * sq_hi[:, i:i + 1])
    for (i, j), col in (((0, 1), 5), ((0, 2), 6), ((1, 2), 8)):
        a = 2.0 * forms[:, col][None, :]
        prods = [lo[:, i:i + 1] * lo[:, j:j + 1], lo[:, i:i + 1] * hi[:, j:j + 1],
                 hi[:, i:i + 1] * lo[:, j:j + 1], hi[:, i:i + 1] * hi[:, j:j + 1]]
        up += np.maximum.reduce([a * p for p in prods])
    return up


def prove_no_cav(vehicles: Sequence[Vehicle], pos: int, spec: CavSpec, *,
                 omega: Array | None = None, max_boxes: int = 400_000) -> Exclusion:
    """Try to prove that no gains within the bounds make the string certified (module docstring).

    Parameters
    ----------
    vehicles : sequence of Vehicle
        The recorded string (the vehicle at ``pos`` is replaced by the CAV).
    pos : int
        The CAV's position, 1-based.
    spec : CavSpec
        The CAV (its τ, δ, T* and gain bounds).
    omega : ndarray, optional
        The frequencies ω_j (default :func:`exclusion_frequencies`).
    max_boxes : int
        The budget: boxes examined in all.

    Returns
    -------
    Exclusion
        ``proven`` only when every box of the bounds is excluded.
    """
    w = exclusion_frequencies() if omega is None else np.asarray(omega, dtype=float)
    fG, _, err = cav_forms(vehicles, pos, spec, w)
    forms = fG.T.copy()  # (m, 10)
    lo_b, hi_b = spec.bounds
    B = max(abs(lo_b), abs(hi_b))
    slack = err * (1.0 + 3.0 * B + 9.0 * B * B)
    zero = w == 0
    # G(0)/k_x: the linear form b_x + A_xx k_x + 2 A_xv k_v + 2 A_xa k_a (module docstring)
    lin = forms[zero]
    forms[zero] = 0.0
    forms[zero, 0] = lin[:, 1]
    forms[zero, 1] = lin[:, 4]
    forms[zero, 2] = 2.0 * lin[:, 5]
    forms[zero, 3] = 2.0 * lin[:, 6]
    slack[zero] = err[zero] * (1.0 + 5.0 * B)
    # the rounding of quadratic_upper itself: a relative 1e-12 of the sum of its terms' sizes
    size = np.abs(forms) @ np.array([1, B, B, B, B * B, 2 * B * B, 2 * B * B, B * B, 2 * B * B, B * B])
    slack = slack + 1e-12 * size
    T = spec.headway - spec.tau
    lo = spec.lower()[None, :].copy()
    hi = spec.upper()[None, :].copy()
    width0 = hi_b - lo_b
    examined = 0
    while lo.shape[0]:
        examined += lo.shape[0]
        # the CAV's Hurwitz conditions k_x > 0 and k_v + (T* − τ) k_x > 0 fail on the whole box
        kx_max = hi[:, 0]
        out = kx_max <= 0  # D(0) = k_x ≤ 0: a root at s ≥ 0, with or without θ_r
        if spec.reaction_delay == 0:
            out |= (hi[:, 1] + np.maximum(T * lo[:, 0], T * hi[:, 0])) <= 0
        up = quadratic_upper(forms, lo, hi)
        out |= np.any(up < -slack[None, :], axis=1)
        lo, hi = lo[~out], hi[~out]
        if not lo.shape[0]:
            return Exclusion(True, examined, 0, w.size)
        if examined + 2 * lo.shape[0] > max_boxes or np.min(hi - lo) < 1e-12 * width0:
            return Exclusion(False, examined, int(lo.shape[0]), w.size)
        d = np.argmax((hi - lo), axis=1)
        rows = np.arange(lo.shape[0])
        mid = 0.5 * (lo[rows, d] + hi[rows, d])
        lo2, hi2 = lo.copy(), hi.copy()
        hi[rows, d] = mid
        lo2[rows, d] = mid
        lo, hi = np.vstack([lo, lo2]), np.vstack([hi, hi2])
    return Exclusion(True, examined, 0, w.size)
