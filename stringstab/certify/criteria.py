"""Vectorised string-stability criteria: Hurwitz, Proposition 1 and the types I-IV.

All functions broadcast over arrays of gains (and parameters) and evaluate the
*derived* SymPy expressions of :mod:`stringstab.derive.symbolic` (or, for the
``printed`` source, those of :mod:`stringstab.derive.printed`) through the numeric code
generated from them (:mod:`stringstab.derive.generated`, ``python -m stringstab.derive.codegen``),
so no SymPy is imported at run time.

Two Taylor-based verdicts are offered, because they differ:

``derived``
    the derived Ψ1, Ψ2, Ψ3, Λ (exact-delay series) with the *corrected* logic of
    Proposition 1: Ψ1ω⁴ + Ψ2ω² + Ψ3 ≥ 0 for all ω² ≥ 0 iff
    Ψ1 ≥ 0 ∧ Ψ3 ≥ 0 ∧ (Ψ2 ≥ 0 ∨ Λ ≤ 0);
``printed``
    the IDL paper's printed eqs 12-15 with its printed logic
    (Ψ1, Ψ2, Ψ3 ≥ 0) ∨ Λ ≤ 0, as a reader of the paper would apply it.

Neither is a certificate (they truncate the frequency series at ω⁶); see
:mod:`stringstab.certify.continuous` for the exact one.

References
----------
IDL paper, Proposition 1 (eqs 12-15) and §3.3 (types I-IV).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from ..derive import generated as _gen
from ..errors import StringStabError
from ..params import as_gains, check_params

__all__ = [
    "HURWITZ_LABELS",
    "HURWITZ_RTOL",
    "TYPE_NAMES",
    "TaylorCriteria",
    "hurwitz",
    "hurwitz_bands",
    "hurwitz_bands_kernel",
    "hurwitz_conditions",
    "hurwitz_gradients",
    "hurwitz_margin",
    "hurwitz_margin_kernel",
    "hurwitz_ok",
    "proposition1",
    "psi",
    "stability_type",
    "taylor_criteria",
    "taylor_criteria_kernel",
]

Array = npt.NDArray[np.float64]

#: Names of the stability types of IDL §3.3, indexed by the integer codes 1-4.
TYPE_NAMES: dict[int, str] = {1: "I", 2: "II", 3: "III", 4: "IV"}
#: The Hurwitz conditions of :func:`hurwitz_conditions`, as people write them.
HURWITZ_LABELS: tuple[str, ...] = ("k_x", "k_v + (T* - tau) k_x")
_PSI = {"derived": _gen.psi_derived, "printed": _gen.psi_printed}


def psi(
    k_x: npt.ArrayLike, k_v: npt.ArrayLike, k_a: npt.ArrayLike,
    *, tau: npt.ArrayLike, delta: npt.ArrayLike, headway: npt.ArrayLike, source: str = "derived",
) -> tuple[Array, Array, Array, Array]:
    """Ψ1, Ψ2, Ψ3 and Λ = Ψ2² − 4Ψ1Ψ3 (IDL eqs 12-15), broadcast together.

    ``source="derived"``: :func:`stringstab.derive.symbolic.derived_psi` (exact-delay series);
    ``"printed"``: the IDL paper's eqs 12-14 as printed (:mod:`stringstab.derive.printed`).
    Λ is evaluated from Ψ1-Ψ3 by its definition (eq 15) rather than from its expanded
    form (~4x slower in NumPy and no more accurate).

    Parameters
    ----------
    k_x, k_v, k_a : array_like
        Gains of the controller u = k_x Δp + k_v Δv + k_a a_{i-1}(t − δ) (IDL eq 4):
        k_x in 1/s², k_v in 1/s, k_a dimensionless.
    tau : array_like
        Actuator lag τ, s.
    delta : array_like
        Communication delay δ, s.
    headway : array_like
        Desired time headway T*, s.
    source : {"derived", "printed"}
        Which Ψ expressions to evaluate (see above).

    Returns
    -------
    psi1, psi2, psi3, lam : ndarray
        Ψ1, Ψ2, Ψ3 (IDL eqs 12-14) and Λ (eq 15), all of the broadcast shape of the inputs.

    Raises
    ------
    StringStabError
        If ``source`` is neither ``"derived"`` nor ``"printed"`` (a ValueError).

    Examples
    --------
    >>> [round(float(v), 6) for v in psi(1.0, 0.5, 0.2, tau=0.1, delta=0.2, headway=1.1)]
    [0.010293, 0.592, 0.71, 0.321231]
    """
    try:
        fn = _PSI[source]
    except KeyError:
        raise StringStabError(f"source must be 'derived' or 'printed'; got {source!r}") from None
    args = (k_x, k_v, k_a, tau, delta, headway)
    shape = np.broadcast_shapes(*(np.shape(v) for v in args))
    p1, p2, p3 = (np.broadcast_to(np.asarray(o, dtype=float), shape)
                  for o in fn(*(np.asarray(v, dtype=float) for v in args)))
    return p1, p2, p3, p2 * p2 - 4.0 * p1 * p3


def hurwitz_conditions(
    k_x: npt.ArrayLike, k_v: npt.ArrayLike, k_a: npt.ArrayLike = 0.0,
    *, tau: float, headway: float,
) -> tuple[Array, ...]:
    """The values of the Hurwitz conditions of Γ's denominator; each must be > 0.

    Generated from :func:`stringstab.derive.symbolic.hurwitz_conditions`: k_x and
    k_v + (T* − τ)k_x (:data:`HURWITZ_LABELS`).  Works on arrays and on floats.

    Parameters
    ----------
    k_x, k_v : array_like
        Position gain k_x (1/s²) and velocity gain k_v (1/s).
    k_a : array_like
        Acceleration-feedforward gain (dimensionless); it does not enter the
        denominator and is accepted for a uniform call.
    tau : float
        Actuator lag τ, s.
    headway : float
        Desired time headway T*, s.

    Returns
    -------
    tuple of ndarray or float
        The values of the conditions, in the order of :data:`HURWITZ_LABELS`;
        Γ is internally stable iff all are > 0 (given τ > 0).

    Examples
    --------
    >>> [float(c) for c in hurwitz_conditions(1.0, 0.5, tau=0.1, headway=1.1)]
    [1.0, 1.5]
    """
    return tuple(_gen.hurwitz_conditions(k_x, k_v, k_a, tau, 0.0, headway))


def hurwitz_gradients(*, tau: float, headway: float) -> Array:
    """∇_K of each Hurwitz condition (they are linear in K): one row per condition.

    Parameters
    ----------
    tau : float
        Actuator lag τ, s.
    headway : float
        Desired time headway T*, s.

    Returns
    -------
    ndarray, shape (n_conditions, 3)
        Row j is ∂c_j/∂(k_x, k_v, k_a) of condition j of :func:`hurwitz_conditions`.

    Examples
    --------
    >>> hurwitz_gradients(tau=0.1, headway=1.1).tolist()
    [[1.0, 0.0, 0.0], [1.0, 1.0, 0.0]]
    """
    flat = np.asarray(_gen.hurwitz_gradients(tau, 0.0, headway), dtype=float)
    return flat.reshape(-1, 3)


def hurwitz_ok(k_x: float, k_v: float, k_a: float = 0.0, *, tau: float, headway: float,
               margin: float = 0.0) -> bool:
    """Scalar form of :func:`hurwitz` for inner loops: every condition > ``margin``.

    Parameters
    ----------
    k_x, k_v, k_a : float
        Gains (k_x in 1/s², k_v in 1/s, k_a dimensionless; k_a does not enter).
    tau : float
        Actuator lag τ, s.
    headway : float
        Desired time headway T*, s.
    margin : float
        Absolute amount each condition must exceed (0: strict inequalities).

    Returns
    -------
    bool
        True iff every Hurwitz condition of :func:`hurwitz_conditions` is > ``margin``.
    """
    return all(c > margin for c in _gen.hurwitz_conditions(k_x, k_v, k_a, tau, 0.0, headway))


def hurwitz(
    k_x: npt.ArrayLike, k_v: npt.ArrayLike, k_a: npt.ArrayLike = 0.0,
    *, tau: float, headway: float, rtol: float = 0.0,
) -> npt.NDArray[np.bool_]:
    """Internal stability of Γ: whether τs³ + s² + (k_v + T*k_x)s + k_x is Hurwitz.

    The conditions, derived by :func:`stringstab.derive.symbolic.hurwitz_conditions`, are
    k_x > 0 and k_v + (T* − τ)k_x > 0 (with τ > 0).  ``rtol`` demands each
    condition exceed ``rtol`` times the scale of its terms (a margin).

    Parameters
    ----------
    k_x, k_v, k_a : array_like
        Gains (k_a does not enter the denominator; accepted for a uniform call).
    tau, headway : float
        Actuator lag τ > 0 and desired headway T*, s.
    rtol : float
        Relative margin each condition must exceed (0: strict inequalities).

    Returns
    -------
    ndarray of bool
        True where the closed loop is internally stable.

    Examples
    --------
    >>> hurwitz([1.0, -1.0, 1.0], [0.5, 0.5, -1.2], tau=0.1, headway=1.1)
    array([ True, False, False])
    """
    kx, kv, ka = as_gains(k_x, k_v, k_a)
    return _hurwitz(kx, kv, ka, tau, headway, rtol)


def _hurwitz(kx: Array, kv: Array, ka: Array, tau: float, headway: float,
             rtol: float) -> npt.NDArray[np.bool_]:
    """:func:`hurwitz` of checked gains."""
    conds = _gen.hurwitz_conditions(kx, kv, ka, tau, 0.0, headway)
    if rtol:
        scales = _gen.hurwitz_scales(kx, kv, ka, tau, 0.0, headway)
        ok = [c > rtol * sc for c, sc in zip(conds, scales)]
    else:
        ok = [c > 0 for c in conds]
    return np.asarray(np.logical_and.reduce(ok) & np.ones(kx.shape, dtype=bool))


#: Relative band around the Hurwitz boundary that the certificates leave inconclusive.
HURWITZ_RTOL = 1e-12


def hurwitz_bands(
    k_x: npt.ArrayLike, k_v: npt.ArrayLike, *, tau: float, headway: float,
) -> tuple[npt.NDArray[np.bool_], npt.NDArray[np.bool_]]:
    """(surely Hurwitz, surely not Hurwitz): neither within a relative 10⁻¹² of the boundary.

    The certificates' internal-stability decision (:data:`HURWITZ_RTOL`): a triple in
    neither set is left inconclusive.

    Parameters
    ----------
    k_x, k_v : array_like
        Position gain k_x (1/s²) and velocity gain k_v (1/s), broadcast together.
    tau : float
        Actuator lag τ, s.
    headway : float
        Desired time headway T*, s.

    Returns
    -------
    sure, fail : ndarray of bool
        ``sure``: Hurwitz with relative margin :data:`HURWITZ_RTOL`; ``fail``: not
        Hurwitz even with the margin −:data:`HURWITZ_RTOL`.  A triple in neither is
        within the band around the boundary.

    Examples
    --------
    >>> [v.tolist() for v in hurwitz_bands([1.0, -1.0, 0.0], 0.5, tau=0.1, headway=1.1)]
    [[True, False, False], [False, True, True]]
    """
    kx, kv, _ = as_gains(k_x, k_v, 0.0)
    return hurwitz_bands_kernel(kx, kv, tau=tau, headway=headway)


def hurwitz_bands_kernel(
    kx: Array, kv: Array, *, tau: float, headway: float,
) -> tuple[npt.NDArray[np.bool_], npt.NDArray[np.bool_]]:
    """:func:`hurwitz_bands` of gains already checked by :mod:`stringstab.certify`'s way in.

    Parameters
    ----------
    kx, kv : ndarray of float64
        Position and velocity gains, finite, of one shape.
    tau, headway : float
        Actuator lag τ > 0 and desired headway T* ≥ 0, s (checked).

    Returns
    -------
    sure, fail : ndarray of bool
        As for :func:`hurwitz_bands`.
    """
    ka = np.zeros_like(kx)
    sure = _hurwitz(kx, kv, ka, tau, headway, HURWITZ_RTOL)
    fail = ~_hurwitz(kx, kv, ka, tau, headway, -HURWITZ_RTOL)
    return sure, fail


def hurwitz_margin(
    k_x: npt.ArrayLike, k_v: npt.ArrayLike, *, tau: float, headway: float
) -> Array:
    """Decay rate −max Re(p) over the poles p of Γ (> 0 iff internally stable).

    Computed as the eigenvalues of the companion matrices, vectorised.

    Parameters
    ----------
    k_x, k_v : array_like
        Position gain k_x (1/s²) and velocity gain k_v (1/s), broadcast together.
    tau : float
        Actuator lag τ, s.
    headway : float
        Desired time headway T*, s.

    Returns
    -------
    ndarray
        −max Re(p) over the three roots of τs³ + s² + (k_v + T*k_x)s + k_x, in 1/s,
        of the broadcast shape of the gains.

    Examples
    --------
    >>> float(np.round(hurwitz_margin(1.0, 0.5, tau=0.1, headway=1.1), 4))
    0.9016
    """
    kx, kv, _ = as_gains(k_x, k_v, 0.0)
    return hurwitz_margin_kernel(kx, kv, tau=tau, headway=headway)


def hurwitz_margin_kernel(kx: Array, kv: Array, *, tau: float, headway: float) -> Array:
    """:func:`hurwitz_margin` of gains already checked by :mod:`stringstab.certify`'s way in.

    Parameters
    ----------
    kx, kv : ndarray of float64
        Position and velocity gains, finite, of one shape.
    tau, headway : float
        Actuator lag τ > 0 and desired headway T* ≥ 0, s (checked).

    Returns
    -------
    ndarray
        −max Re(p) over the poles of Γ, 1/s, of the gains' shape.
    """
    shape = kx.shape
    kx, kv = kx.ravel(), kv.ravel()
    n = kx.size
    lead, *rest = (np.broadcast_to(np.asarray(c, dtype=float), (n,))
                   for c in _gen.denominator_coefficients(kx, kv, 0.0, tau, 0.0, headway))
    C = np.zeros((n, 3, 3))
    C[:, 0, :] = -np.stack([r / lead for r in rest], axis=1)  # companion matrix of D(s)
    C[:, 1, 0] = 1.0
    C[:, 2, 1] = 1.0
    ev = np.linalg.eigvals(C) if n else np.zeros((0, 3))
    return np.asarray(-ev.real.max(axis=1).reshape(shape))


def stability_type(psi2: npt.ArrayLike, psi3: npt.ArrayLike, lam: npt.ArrayLike) -> npt.NDArray[np.int8]:
    """Stability type 1-4 (I-IV) of IDL §3.3 from Ψ2, Ψ3 and Λ.

    I: Ψ2 ≥ 0 and Ψ3 ≥ 0; II: Ψ3 ≥ 0, Ψ2 < 0, Λ ≤ 0; III: Ψ3 < 0;
    IV: Ψ3 ≥ 0, Ψ2 < 0, Λ > 0.


    Parameters
    ----------
    psi2, psi3, lam : array_like
        Ψ2, Ψ3 and Λ = Ψ2² − 4Ψ1Ψ3 (IDL eqs 13-15), broadcast together.

    Returns
    -------
    ndarray of int8
        1, 2, 3 or 4 for types I-IV.

    Examples
    --------
    >>> stability_type([1.0, -1.0, 1.0, -1.0], [1.0, 1.0, -1.0, 1.0], [0.0, -1.0, 0.0, 2.0])
    array([1, 2, 3, 4], dtype=int8)
    """
    p2, p3, lm = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (psi2, psi3, lam)))
    t = np.full(p2.shape, 4, dtype=np.int8)
    t[(p3 >= 0) & (p2 < 0) & (lm <= 0)] = 2
    t[(p3 >= 0) & (p2 >= 0)] = 1
    t[p3 < 0] = 3
    return t


@dataclass(frozen=True)
class TaylorCriteria:
    """Ψ1, Ψ2, Ψ3, Λ, the Proposition-1 sign test's answer and the type, as arrays.

    The answer (``stable``, output key ``"sign"``) of a test on a Taylor approximation of the
    delay is ``"stable"`` / ``"unstable"``, never a certificate's verdict (IDL Proposition 1:
    the signs of Ψ1, Ψ2, Ψ3 and Λ).
    """

    source: str
    psi1: Array
    psi2: Array
    psi3: Array
    lam: Array
    stable: npt.NDArray[np.bool_]
    type: npt.NDArray[np.int8]

    def row(self, i: Any) -> dict[str, Any]:
        """The JSON object ``{"psi1","psi2","psi3","lambda","sign","type"}`` of element i.

        Parameters
        ----------
        i : int or tuple of int
            Index into the arrays.

        Returns
        -------
        dict
            Ψ1, Ψ2, Ψ3, Λ as floats, Proposition 1's answer from their signs (``"sign"``:
            ``"stable"``/``"unstable"``, not a verdict) and the type (``"I"``-``"IV"``).
        """
        return {
            "psi1": float(self.psi1[i]),
            "psi2": float(self.psi2[i]),
            "psi3": float(self.psi3[i]),
            "lambda": float(self.lam[i]),
            "sign": "stable" if bool(self.stable[i]) else "unstable",
            "type": TYPE_NAMES[int(self.type[i])],
        }


def taylor_criteria(
    k_x: npt.ArrayLike, k_v: npt.ArrayLike, k_a: npt.ArrayLike,
    *, tau: float, delta: float, headway: float, source: str = "derived",
) -> TaylorCriteria:
    """Proposition 1 (IDL eqs 12-15) and the type I-IV, vectorised.

    Parameters
    ----------
    k_x, k_v, k_a : array_like
        Gains (broadcast together).
    tau, delta, headway : float
        Model parameters.
    source : {"derived", "printed"}
        ``"derived"``: derived Ψ with the corrected logic; ``"printed"``: the
        printed Ψ with the printed logic (see the module docstring).

    Returns
    -------
    TaylorCriteria

    Examples
    --------
    >>> c = taylor_criteria(0.9, -0.5, 1.1, tau=0.1, delta=0.2, headway=1.1)
    >>> bool(c.stable), int(c.type)
    (False, 4)
    """
    tau, delta, headway = check_params(tau, delta, headway)
    kx, kv, ka = as_gains(k_x, k_v, k_a)
    return taylor_criteria_kernel(kx, kv, ka, tau=tau, delta=delta, headway=headway, source=source)


def taylor_criteria_kernel(
    kx: Array, kv: Array, ka: Array, *, tau: float, delta: float, headway: float,
    source: str = "derived",
) -> TaylorCriteria:
    """:func:`taylor_criteria` of inputs already checked by :mod:`stringstab.certify`'s way in.

    Parameters
    ----------
    kx, kv, ka : ndarray of float64
        Gains, finite, of one shape.
    tau, delta, headway : float
        τ > 0, δ ≥ 0, T* ≥ 0, s (checked).
    source : {"derived", "printed"}
        As for :func:`taylor_criteria`.

    Returns
    -------
    TaylorCriteria
    """
    psi1, psi2, psi3, lam = psi(kx, kv, ka, tau=tau, delta=delta, headway=headway, source=source)
    return TaylorCriteria(
        source, psi1, psi2, psi3, lam, proposition1(psi1, psi2, psi3, lam, source=source),
        stability_type(psi2, psi3, lam),
    )


def proposition1(
    psi1: npt.ArrayLike, psi2: npt.ArrayLike, psi3: npt.ArrayLike, lam: npt.ArrayLike,
    *, source: str = "derived",
) -> npt.NDArray[np.bool_]:
    """The Proposition-1 verdict from Ψ1, Ψ2, Ψ3, Λ (IDL eqs 12-15).

    ``source="derived"``: the corrected logic Ψ1 ≥ 0 ∧ Ψ3 ≥ 0 ∧ (Ψ2 ≥ 0 ∨ Λ ≤ 0);
    ``"printed"``: the printed (Ψ1, Ψ2, Ψ3 ≥ 0) ∨ Λ ≤ 0 (module docstring).

    Parameters
    ----------
    psi1, psi2, psi3, lam : array_like
        Ψ1, Ψ2, Ψ3 (IDL eqs 12-14) and Λ (eq 15), broadcast together, e.g. from :func:`psi`.
    source : {"derived", "printed"}
        Which logic to apply (see above).

    Returns
    -------
    ndarray of bool
        True where the (Taylor-truncated) criterion declares string stability.

    Raises
    ------
    StringStabError
        If ``source`` is neither ``"derived"`` nor ``"printed"`` (a ValueError).

    Examples
    --------
    >>> proposition1(-0.1, -1.0, -1.0, -1.0, source="printed"), proposition1(-0.1, -1.0, -1.0, -1.0)
    (array(True), array(False))
    """
    p1, p2, p3, lm = (np.asarray(v, dtype=float) for v in (psi1, psi2, psi3, lam))
    if source == "derived":
        return np.asarray((p1 >= 0) & (p3 >= 0) & ((p2 >= 0) | (lm <= 0)))
    if source == "printed":
        return np.asarray(((p1 >= 0) & (p2 >= 0) & (p3 >= 0)) | (lm <= 0))
    raise StringStabError(f"source must be 'derived' or 'printed'; got {source!r}")
