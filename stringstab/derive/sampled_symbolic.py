r"""Symbolic derivation of the sampled-data (zero-order hold) string transfer function H(z).

Every vehicle of a homogeneous platoon samples synchronously with period H
(``sample_time``), holds its command over each period (zero-order hold), and has the
actuator lag of the IDL paper, τ ȧ = u − a (eq 7).  The command is the IDL law (eq 4)
evaluated at the sampling instants,

.. math::
    u_k = k_x Δp(kH) + k_v Δv(kH) + k_a\,a_{i-1}(kH - δ),

where the delayed predecessor acceleration is the *exact* continuous-time value
a_{i−1}(kH − δ) for any δ ≥ 0 (δ = mH + εH, m integer, 0 ≤ ε < 1), not an interpolation.

Nothing below is typed in from a paper.  The derivation is:

1. **State equations** of the follower (IDL eqs 5-9; :func:`stringstab.derive.symbolic.vehicle_model`)
   augmented with the predecessor's acceleration a_p (lag τ_p, its own held command u_p)
   and the two held commands: a linear ODE with constant inputs over a period.
2. **Exact discretisation**: Φ = exp(A_aug H), the SymPy matrix exponential
   (:func:`sampled_model`).  Between samples the predecessor's acceleration is
   a_p(jH + s) = u_{p,j} + (a_{p,j} − u_{p,j}) e^{−s/τ_p}; its samples obey
   a_{p,j+1} = E_p a_{p,j} + (1 − E_p) u_{p,j}, E_p = e^{−H/τ_p}, so its held command is
   the exact function U_p(z) = (z − E_p)/(1 − E_p) A_p(z) of its acceleration samples.
3. **The delayed sample** (modified z-transform): kH − δ = (k − m − 1)H + (1 − ε)H, so
   a_{i−1}(kH − δ) = C a_{p,k−m−1} + (1 − C) u_{p,k−m−1} with C = e^{−(1−ε)H/τ_p}, i.e.
   z^{−(m+1)} [C + (1 − C)(z − E_p)/(1 − E_p)] A_p(z)  (ε = 0 gives z^{−m} A_p(z)).
4. **z-domain**: closing the loop u_k = K x_k + k_a d_k gives
   H(z) = A_i(z)/A_{i−1}(z) = (N_0(z) + z^{−(m+1)} N_1(z))/D(z) (:func:`sampled_transfer`).

The chain variable is the acceleration sample sequence: H(z) maps the predecessor's
acceleration samples to the follower's, for a predecessor that is itself a
zero-order-hold lag vehicle (every vehicle after the first; the first follows a leader
whose acceleration is arbitrary).  Its poles are the roots of the follower's closed-loop
characteristic polynomial Δ(z) (:func:`characteristic_polynomial`) and m + 1 poles at
z = 0; internal stability is Schur stability of Δ (:func:`schur_conditions`).

In the variable w = z − 1 (the delta operator) every coefficient is a sum of terms of one
order in H (:func:`w_coefficients`), which is what the numeric certificate
(:mod:`stringstab.certify.sampled`) evaluates.

Symbols: the gains and ``tau``, ``delta``, ``headway`` of :mod:`stringstab.derive.symbolic`,
plus ``sample_time`` (H), ``tau_prev`` (τ_p, the predecessor's lag; τ_p = τ in a
homogeneous platoon), ``epsilon`` (ε, the fractional part of δ/H), ``m`` (its integer
part), ``z`` and ``w``.

References
----------
IDL paper, eqs 3-9 (model) and eq 4 (control law).
E. I. Jury, *Theory and Application of the z-Transform Method*, Wiley (1964): the
modified z-transform and the bilinear (Schur-Hurwitz) transformation.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import sympy as sp

from .symbolic import k_a, k_v, k_x, routh_hurwitz, tau, vehicle_model

__all__ = [
    "SAMPLED_SUBSTITUTABLE",
    "W_COEFFICIENT_NAMES",
    "SampledModel",
    "SampledTransferFunction",
    "characteristic_polynomial",
    "dc_margin",
    "derive_sampled_all",
    "epsilon",
    "m",
    "phi_functions",
    "sample_time",
    "sampled_model",
    "sampled_transfer",
    "schur_conditions",
    "tau_prev",
    "w",
    "w_coefficients",
    "z",
]

sample_time = sp.Symbol("sample_time", positive=True)
tau_prev = sp.Symbol("tau_prev", positive=True)
epsilon = sp.Symbol("epsilon", nonnegative=True)
m = sp.Symbol("m", integer=True, nonnegative=True)
z = sp.Symbol("z")
w = sp.Symbol("w")

# placeholders for rational algebra: the exponentials and the delay operator z^{-(m+1)}
_E, _Ep, _C, _Zd = sp.symbols("E_lag E_prev C_frac Z_delay", positive=True)


@dataclass(frozen=True)
class SampledModel:
    """The exactly discretised follower-predecessor pair (step 2 of the module docstring).

    Attributes
    ----------
    state : tuple of Symbol
        Augmented state [Δp, Δv, a_i, a_p, u_p, u]; u_p and u are held (zero derivative).
    A : sympy.Matrix
        The continuous-time 6×6 matrix of the augmented ODE.
    Phi : sympy.Matrix
        exp(A H), the exact transition over one sampling period.
    """

    state: tuple[sp.Symbol, ...]
    A: sp.Matrix
    Phi: sp.Matrix


@lru_cache(maxsize=1)
def sampled_model() -> SampledModel:
    """Augment the follower's state equations and discretise them exactly.

    The follower's rows are the IDL model (M1, M2, M3 of
    :func:`stringstab.derive.symbolic.vehicle_model`); the predecessor's acceleration obeys
    τ_p ȧ_p = u_p − a_p; both commands are constant over a period (zero-order hold).

    Returns
    -------
    SampledModel

    Examples
    --------
    >>> Phi = sampled_model().Phi
    >>> Phi[2, 2], Phi[2, 5]
    (exp(-sample_time/tau), 1 - exp(-sample_time/tau))
    """
    vm = vehicle_model()
    A = sp.zeros(6, 6)
    A[:3, :3] = vm.M1
    A[:3, 3] = vm.M3  # the predecessor's acceleration drives Δv
    A[:3, 5] = vm.M2  # the follower's own held command
    A[3, 3] = -1 / tau_prev
    A[3, 4] = 1 / tau_prev
    Phi = (A * sample_time).exp()
    Phi = Phi.applyfunc(lambda e: sp.expand(sp.simplify(e)))
    ap, up, u = sp.symbols("a_prev u_prev u", real=True)
    return SampledModel((*vm.state, ap, up, u), A, Phi)


@dataclass(frozen=True)
class SampledTransferFunction:
    """H(z) = (N_0(z) + z^{−(m+1)} N_1(z)) / D(z) from a_{i−1}(kH) to a_i(kH).

    Attributes
    ----------
    numerator_direct : sympy.Expr
        N_0(z), polynomial in z (the spacing and speed feedback path).
    numerator_delayed : sympy.Expr
        N_1(z), polynomial in z, multiplied by z^{−(m+1)} (the k_a feed-forward of the
        delayed sample).
    denominator : sympy.Expr
        D(z) = (1 − E_p) Δ(z), with Δ the monic closed-loop characteristic polynomial.
    """

    numerator_direct: sp.Expr
    numerator_delayed: sp.Expr
    denominator: sp.Expr

    @property
    def expr(self) -> sp.Expr:
        """H(z) as one expression (the delay as z**(-m - 1))."""
        return (self.numerator_direct + z ** (-m - 1) * self.numerator_delayed) / self.denominator


def _exps() -> dict[sp.Expr, sp.Symbol]:
    return {sp.exp(-sample_time / tau): _E, sp.exp(-sample_time / tau_prev): _Ep}


def _back() -> dict[sp.Symbol, sp.Expr]:
    return {
        _E: sp.exp(-sample_time / tau),
        _Ep: sp.exp(-sample_time / tau_prev),
        _C: sp.exp(-(1 - epsilon) * sample_time / tau_prev),
    }


@lru_cache(maxsize=1)
def _transfer_placeholders() -> tuple[sp.Expr, sp.Expr, sp.Expr]:
    """(N_0, N_1, Δ) in z with E, E_p, C as placeholder symbols (steps 3-4)."""
    Phi = sampled_model().Phi.applyfunc(lambda e: sp.expand(e.subs(_exps())))
    F11, Fap, Fup, Fu = Phi[:3, :3], Phi[:3, 3], Phi[:3, 4], Phi[:3, 5]
    P = (z - _Ep) / (1 - _Ep)  # U_p(z) = P(z) A_p(z)
    d = _Zd * (_C + (1 - _C) * P)  # the delayed sample over A_p(z)
    Kx = sp.Matrix([[k_x, k_v, 0]])
    M = z * sp.eye(3) - (F11 + Fu * Kx)
    Delta = sp.expand(M.det())
    num = (sp.Matrix([[0, 0, 1]]) * M.adjugate() * (Fu * k_a * d + Fap + Fup * P))[0, 0]
    num = sp.expand(sp.cancel(num * (1 - _Ep)))
    n1 = sp.factor(num.coeff(_Zd, 1))
    n0 = sp.factor(num.coeff(_Zd, 0))
    return n0, n1, Delta


@lru_cache(maxsize=1)
def sampled_transfer() -> SampledTransferFunction:
    """Derive H(z) from the exact discretisation (step 4 of the module docstring).

    Returns
    -------
    SampledTransferFunction
        With e^{−H/τ}, e^{−H/τ_p} and C = e^{−(1−ε)H/τ_p} written as exponentials.

    Examples
    --------
    >>> tf = sampled_transfer()
    >>> sp.simplify(tf.expr.subs(z, 1))  # DC gain: H(1) = 1
    1
    """
    n0, n1, Delta = _transfer_placeholders()
    back = _back()
    return SampledTransferFunction(
        n0.subs(back), n1.subs(back), sp.factor((1 - _Ep) * Delta).subs(back)
    )


@lru_cache(maxsize=1)
def characteristic_polynomial() -> sp.Expr:
    """Δ(z) = det(zI − Φ_cl), the follower's monic closed-loop characteristic polynomial.

    A cubic in z; it does not depend on δ or τ_p, and T* enters only through
    c = k_v + T* k_x, as in the continuous denominator (IDL eq 11, derived).

    Returns
    -------
    sympy.Expr
        Δ(z), a monic cubic in ``z``.

    Examples
    --------
    >>> sp.Poly(characteristic_polynomial(), z).degree()
    3
    """
    return sp.collect(_transfer_placeholders()[2].subs(_back()), z)


#: Names of the w-coefficients returned by :func:`w_coefficients`.
W_COEFFICIENT_NAMES = ("delta0", "delta1", "delta2", "delta3", "nu0", "nu1", "nu2", "ell0", "ell1")


@lru_cache(maxsize=1)
def w_coefficients() -> dict[str, sp.Expr]:
    r"""Coefficients of H(z) in w = z − 1, derived (the form the numeric code evaluates).

    With w = z − 1,

    .. math::
        H(z) = \frac{1 - E}{1 - E_p}\,
               \frac{n(w) + z^{-(m+1)}\,k_a w^2 \ell(w)}{Δ(w)},\quad
        Δ = \sum_{k=0}^{3} δ_k w^k,\; n = \sum_{k=0}^{2} ν_k w^k,\;
        \ell = \ell_0 + \ell_1 w ,

    where the factor k_a w² (z−1)² of the delayed path is found by SymPy, not assumed.

    Returns
    -------
    dict
        ``delta0``…``delta3``, ``nu0``…``nu2``, ``ell0``, ``ell1`` (see
        :data:`W_COEFFICIENT_NAMES`) as expressions of the model symbols.

    Examples
    --------
    >>> c = w_coefficients()
    >>> c["delta3"], sp.simplify(c["ell0"] - (1 - sp.exp(-sample_time / tau_prev)))
    (1, 0)
    """
    n0, n1, Delta = _transfer_placeholders()
    E = _E
    Dw = sp.Poly(sp.expand(Delta.subs(z, 1 + w)), w)
    # N_0 and N_1 both carry the factor (1 - E): H = (1-E)/(1-E_p) (...)/Δ
    n0w = sp.Poly(sp.expand(sp.cancel(n0 / (1 - E)).subs(z, 1 + w)), w)
    q, r = sp.div(sp.Poly(sp.expand(sp.cancel(n1 / ((1 - E) * k_a)).subs(z, 1 + w)), w),
                  sp.Poly(w**2, w))
    if not r.is_zero:  # pragma: no cover - a property of the model, asserted in tests
        raise AssertionError(f"the delayed path should carry (z-1)^2; remainder {r}")
    back = _back()
    out: dict[str, sp.Expr] = {}
    for k in range(4):
        out[f"delta{k}"] = sp.factor(Dw.coeff_monomial(w**k)).subs(back)
    for k in range(3):
        out[f"nu{k}"] = sp.factor(n0w.coeff_monomial(w**k)).subs(back)
    for k in range(2):
        out[f"ell{k}"] = sp.factor(q.coeff_monomial(w**k)).subs(back)
    return out


@lru_cache(maxsize=1)
def dc_margin() -> sp.Expr:
    """c₂ in |D(e^{jθ})|² − |N(e^{jθ})|² = c₂ θ² + O(θ⁴): the sampled analogue of Ψ3.

    H(1) = 1 makes the θ⁰ term vanish; |H(e^{jθ})| ≤ 1 near θ = 0 requires c₂ ≥ 0.
    Derived in the w-form (w = z − 1, |w|² = ρ ≈ θ², w² = −ρz): the θ² coefficient is
    φ1p²(δ1² − δ0δ1 − 2δ0δ2) − φ1²(ν1² − ν0ν1 − 2ν0ν2) + 2φ1² k_a ℓ0 ν0 with
    φ1 = 1 − e^{−H/τ}, φ1p = 1 − e^{−H/τ_p}.  It does not depend on δ; in a homogeneous
    platoon (τ_p = τ) it is H² φ1⁴ times Ψ3 of the continuous loop (IDL eq 14, derived),
    so the low-frequency condition is the same for every sampling period.

    Returns
    -------
    sympy.Expr
        c₂, the θ² coefficient (in τ, τ_p, H and the gains).

    Examples
    --------
    >>> from stringstab.derive.symbolic import derived_psi
    >>> phi1 = 1 - sp.exp(-sample_time / tau)
    >>> c2 = dc_margin().subs(tau_prev, tau)
    >>> sp.simplify(c2 - sample_time**2 * phi1**4 * derived_psi()[2])
    0
    """
    c = w_coefficients()
    d0, d1, d2 = c["delta0"], c["delta1"], c["delta2"]
    n0, n1, n2 = c["nu0"], c["nu1"], c["nu2"]
    f1 = 1 - sp.exp(-sample_time / tau)
    f1p = 1 - sp.exp(-sample_time / tau_prev)
    return sp.expand(f1p**2 * (d1**2 - d0 * d1 - 2 * d0 * d2)
                     - f1**2 * (n1**2 - n0 * n1 - 2 * n0 * n2) + 2 * f1**2 * k_a * c["ell0"] * n0)


def phi_functions(x: sp.Expr) -> tuple[sp.Expr, sp.Expr, sp.Expr]:
    """φ1 = 1 − e^{−x}, ψ2 = x − φ1, ψ3 = x²/2 − ψ2: the ZOH integrals of the lag.

    Over one period of a lag with x = H/τ: ∫a = τ(ψ2 u + φ1 a), ∫∫a = τ²(ψ3 u + ψ2 a)
    for initial acceleration a and held command u; φ1 ≈ x, ψ2 ≈ x²/2, ψ3 ≈ x³/6 for
    small x (each computed without cancellation by :mod:`stringstab.certify.sampled`).

    Parameters
    ----------
    x : sympy.Expr
        The dimensionless period x = H/τ (sampling period over actuator lag).

    Returns
    -------
    phi1, psi2, psi3 : sympy.Expr
        φ1, ψ2 and ψ3 of ``x``.

    Examples
    --------
    >>> [sp.series(f, sp.Symbol("x"), 0, 4).removeO() for f in phi_functions(sp.Symbol("x"))]
    [x**3/6 - x**2/2 + x, -x**3/6 + x**2/2, x**3/6]
    """
    p1 = 1 - sp.exp(-x)
    p2 = x - p1
    p3 = x**2 / 2 - p2
    return p1, p2, p3


@lru_cache(maxsize=1)
def schur_conditions() -> list[sp.Expr]:
    """Schur stability of a real monic cubic Δ(1 + w) = w³ + δ2 w² + δ1 w + δ0.

    The bilinear map z = (1 + s)/(1 − s) sends the open unit disc onto the open left
    half-plane, so Δ is Schur iff (1 − s)³ Δ((1 + s)/(1 − s)) is Hurwitz; its Hurwitz
    determinants (SymPy, :func:`stringstab.derive.symbolic.routh_hurwitz`) together with its
    leading coefficient give the conditions.  With w = 2s/(1 − s) the transformed cubic
    is 8s³ + 4δ2 s²(1 − s) + 2δ1 s(1 − s)² + δ0 (1 − s)³.

    Returns
    -------
    list of sympy.Expr
        In the symbols ``delta0, delta1, delta2`` (the w-coefficients of
        :func:`w_coefficients`); Δ is Schur iff every expression is > 0.

    Examples
    --------
    >>> schur_conditions()
    [delta0, -3*delta0 + 2*delta1, 3*delta0 - 4*delta1 + 4*delta2,
     -delta0 + 2*delta1 - 4*delta2 + 8,
     -8*delta0**2 + 16*delta0*delta1 - 8*delta0*delta2 - 8*delta0 - 8*delta1**2 + 8*delta1*delta2]
    """
    d0, d1, d2 = sp.symbols("delta0 delta1 delta2", real=True)
    s = sp.Symbol("s")
    ws = 2 * s / (1 - s)
    poly = sp.Poly(sp.expand(sp.cancel((1 - s) ** 3 * (ws**3 + d2 * ws**2 + d1 * ws + d0))), s)
    coeffs = poly.all_coeffs()  # b3, b2, b1, b0
    dets = routh_hurwitz(poly)
    # a cubic with positive leading coefficient is Hurwitz iff every coefficient and the
    # second Hurwitz determinant are positive (the others are implied)
    out = [sp.expand(c) for c in reversed(coeffs)]
    out.append(sp.expand(dets[1]))
    return out


#: Symbols of the sampled derivation a caller may substitute (with those of
#: :data:`stringstab.derive.symbolic.SUBSTITUTABLE`).
SAMPLED_SUBSTITUTABLE: dict[str, sp.Symbol] = {
    str(x): x for x in (sample_time, tau_prev, epsilon, m)
}


def derive_sampled_all(substitute: dict[sp.Symbol, sp.Expr] | None = None) -> dict[str, object]:
    """Every sampled-data expression under stable keys (for ``stringstab derive --sample-time``).

    Keys: ``H`` (one expression), ``H_numerator_direct``, ``H_numerator_delayed``,
    ``H_denominator``, ``characteristic_polynomial``, ``w_coefficients`` (a dict, keys
    :data:`W_COEFFICIENT_NAMES`), ``schur_conditions`` (each > 0, in δ0, δ1, δ2) and
    ``dc_margin``.

    Parameters
    ----------
    substitute : dict, optional
        Symbol → value substitutions applied to every expression (e.g. τ, δ, H, ε, m).

    Returns
    -------
    dict of str to object
        The expressions under the keys listed above.

    Examples
    --------
    >>> d = derive_sampled_all({tau: sp.Rational(1, 10), tau_prev: sp.Rational(1, 10),
    ...                         sample_time: sp.Rational(1, 10)})
    >>> d["w_coefficients"]["delta3"], sorted(d)[:2]
    (1, ['H', 'H_denominator'])
    """
    sub = substitute or {}

    def f(e: sp.Expr) -> sp.Expr:
        return sp.expand(e.subs(sub)) if sub else e

    tf = sampled_transfer()
    return {
        "H": tf.expr.subs(sub) if sub else tf.expr,
        "H_numerator_direct": f(tf.numerator_direct),
        "H_numerator_delayed": f(tf.numerator_delayed),
        "H_denominator": f(tf.denominator),
        "characteristic_polynomial": sp.collect(f(characteristic_polynomial()), z),
        "w_coefficients": {k: f(v) for k, v in w_coefficients().items()},
        "schur_conditions": schur_conditions(),
        "dc_margin": f(dc_margin()),
    }
