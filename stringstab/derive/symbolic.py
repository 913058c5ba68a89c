"""Symbolic model of the IDL controlled vehicle and every formula derived from it.

Nothing here is typed in from the paper: the transfer function Γ(s), the
frequency-domain margin |D(jω)|² − |N(jω)|², the coefficients Ψ1, Ψ2, Ψ3, the
discriminant Λ, their gradients and the Hurwitz conditions are all *computed*
by SymPy from the state-space model of the IDL paper (eqs 3-9).  The printed
forms live in :mod:`stringstab.derive.printed`; :mod:`stringstab.derive.errata` compares.

Symbols (shared by every module): ``k_x k_v k_a`` (gains), ``tau`` (actuator lag
τ), ``delta`` (communication delay δ), ``headway`` (desired time headway T*),
``s`` (Laplace variable) and ``omega`` (angular frequency ω).

References
----------
.. [IDL] Z. Yi, M. Xu, S. Wang, "An integrated deep reinforcement
   learning-linear control strategy for longitudinal control of connected and
   automated vehicles", Transportation Research Part C 184 (2026) 105541.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cache, lru_cache

import numpy as np
import sympy as sp

from ..errors import StringStabError

__all__ = [
    "GAINS",
    "PARAMS",
    "SUBSTITUTABLE",
    "TransferFunction",
    "VehicleModel",
    "delay_parts",
    "delta",
    "derive_all",
    "derived_psi",
    "gamma",
    "gradients",
    "headway",
    "hurwitz_conditions",
    "k_a",
    "k_v",
    "k_x",
    "lambdify_psi",
    "margin_coefficients",
    "margin_exact",
    "margin_series",
    "omega",
    "parse_substitutions",
    "routh_hurwitz",
    "s",
    "tau",
    "vehicle_model",
]

k_x, k_v, k_a = sp.symbols("k_x k_v k_a", real=True)
tau, delta, headway = sp.symbols("tau delta headway", positive=True)
s = sp.Symbol("s")
omega = sp.Symbol("omega", positive=True)
#: The gain vector K = [k_x, k_v, k_a] of eq 4.
GAINS: tuple[sp.Symbol, sp.Symbol, sp.Symbol] = (k_x, k_v, k_a)
#: The model parameters (τ, δ, T*).
PARAMS: tuple[sp.Symbol, sp.Symbol, sp.Symbol] = (tau, delta, headway)

# Internal placeholder for e^{-δs} while doing rational algebra.
_E = sp.Symbol("E_delay")


@dataclass(frozen=True)
class VehicleModel:
    """The controlled follower as data (IDL paper eqs 4-9).

    Attributes
    ----------
    state : tuple of Symbol
        x = [Δp, Δv, a_i]: spacing error, relative speed, own acceleration.
    M1, M2, M3 : sympy.Matrix
        ẋ = M1 x + M2 u + M3 a_{i-1} (eq 8), obtained as Jacobians of the
        state equations, not typed in.
    u : sympy.Expr
        The control law u = k_x Δp + k_v Δv + k_a a_{i-1}(t−δ) (eq 4), with
        the delayed predecessor acceleration as the symbol ``a_prev_delayed``.
    a_prev, a_prev_delayed, u_symbol : Symbol
        Input symbols.
    """

    state: tuple[sp.Symbol, sp.Symbol, sp.Symbol]
    M1: sp.Matrix
    M2: sp.Matrix
    M3: sp.Matrix
    u: sp.Expr
    a_prev: sp.Symbol
    a_prev_delayed: sp.Symbol
    u_symbol: sp.Symbol


@lru_cache(maxsize=1)
def vehicle_model() -> VehicleModel:
    r"""Build the state-space model of eqs 5-9 from the kinematics.

    The spacing error is Δp = Δx − (v_i T* + l_0) (eqs 3-4), so with the
    third-order vehicle (eqs 5-7)

    .. math::
        \dot{Δp} = Δv − T^* a_i,\quad \dot{Δv} = a_{i-1} − a_i,\quad
        \dot a_i = (u − a_i)/τ .

    Returns
    -------
    VehicleModel
        With M1, M2, M3 the Jacobians of these right-hand sides (eq 9).

    Examples
    --------
    >>> m = vehicle_model()
    >>> m.M1
    Matrix([
    [0, 1, -headway],
    [0, 0,       -1],
    [0, 0,   -1/tau]])
    """
    dp, dv, a = sp.symbols("Delta_p Delta_v a_i", real=True)
    a_prev, a_prev_d, u = sp.symbols("a_prev a_prev_delayed u", real=True)
    x = sp.Matrix([dp, dv, a])
    rhs = sp.Matrix([dv - headway * a, a_prev - a, (u - a) / tau])
    M1 = rhs.jacobian(x)
    M2 = rhs.jacobian(sp.Matrix([u]))
    M3 = rhs.jacobian(sp.Matrix([a_prev]))
    law = k_x * dp + k_v * dv + k_a * a_prev_d
    return VehicleModel((dp, dv, a), M1, M2, M3, law, a_prev, a_prev_d, u)


@dataclass(frozen=True)
class TransferFunction:
    """Γ(s) = N(s)/D(s) from a_{i-1} to a_i, with the exact delay e^{−δs}.

    Attributes
    ----------
    numerator : sympy.Expr
        N(s), polynomial in s and e^{−δs}.
    denominator : sympy.Expr
        D(s), a polynomial in s normalised so that its s³ coefficient is τ.
    """

    numerator: sp.Expr
    denominator: sp.Expr

    @property
    def expr(self) -> sp.Expr:
        """Γ(s) as one expression."""
        return self.numerator / self.denominator

    def coeffs(self) -> list[sp.Expr]:
        """Denominator coefficients, highest power of s first."""
        return sp.Poly(self.denominator, s).all_coeffs()


@lru_cache(maxsize=1)
def gamma() -> TransferFunction:
    """Compute Γ(s) = A_i(s)/A_{i−1}(s) from the state space (IDL eq 11, derived).

    Substituting the control law (eq 4) into eq 8 gives the closed loop
    ẋ = (M1 + M2 K_x) x + (M3 + M2 k_a e^{−δs}) a_{i−1} with
    K_x = [k_x, k_v, 0]; Γ(s) = C (sI − A_cl)^{−1} B with C = [0, 0, 1].

    Returns
    -------
    TransferFunction

    Examples
    --------
    >>> g = gamma()
    >>> g.numerator
    k_a*s**2*exp(-delta*s) + k_v*s + k_x
    >>> sp.collect(g.denominator, s)
    k_x + s**3*tau + s**2 + s*(headway*k_x + k_v)
    """
    m = vehicle_model()
    Kx = sp.Matrix([[k_x, k_v, 0]])
    A_cl = m.M1 + m.M2 * Kx
    B = m.M3 + m.M2 * k_a * _E
    C = sp.Matrix([[0, 0, 1]])
    sI_A = s * sp.eye(3) - A_cl
    det = sp.expand(sI_A.det())
    num = sp.expand((C * sI_A.adjugate() * B)[0, 0])
    # normalise: multiply numerator and denominator so D has s^3 coefficient tau
    lead = sp.Poly(det, s).LC()
    scale = tau / lead
    num = sp.expand(sp.simplify(num * scale))
    den = sp.expand(sp.simplify(det * scale))
    num = num.subs(_E, sp.exp(-delta * s))
    return TransferFunction(num, den)


def delay_parts(num: sp.Expr) -> tuple[sp.Expr, sp.Expr]:
    """The parts of a numerator N(s) = n0(s) + n1(s) e^{−δs} (IDL eq 11's delayed term apart).

    Parameters
    ----------
    num : sympy.Expr
        A numerator in s holding ``exp(-delta*s)`` (e.g. ``gamma().numerator``).

    Returns
    -------
    n0, n1 : sympy.Expr
        The undelayed part and the coefficient of e^{−δs}.
    """
    e = sp.exp(-delta * s)
    expr = sp.expand(num.subs(e, _E))
    n1 = expr.coeff(_E, 1)
    n0 = sp.expand(expr - n1 * _E)
    return n0, n1


def _abs2_at_jomega(re: sp.Expr, im: sp.Expr) -> sp.Expr:
    return sp.expand(re**2 + im**2)


@cache
def margin_exact() -> sp.Expr:
    """The exact frequency-domain margin F(ω) = |D(jω)|² − |N(jω)|².

    |Γ(jω)| ≤ 1 for all ω ≥ 0 (eq 10, for an internally stable Γ) if and only if
    F(ω) ≥ 0 for all ω ≥ 0.  The delay enters exactly, as cos(δω) and sin(δω).

    Returns
    -------
    sympy.Expr
        F as a function of ``omega`` and the gains and parameters.
    """
    g = gamma()
    jw = sp.I * omega
    d = sp.expand(g.denominator.subs(s, jw))
    d_re, d_im = d.as_real_imag()
    n0, n1 = delay_parts(g.numerator)
    n = sp.expand(
        n0.subs(s, jw) + n1.subs(s, jw) * (sp.cos(delta * omega) - sp.I * sp.sin(delta * omega))
    )
    n_re, n_im = n.as_real_imag()
    F = sp.expand(_abs2_at_jomega(d_re, d_im) - _abs2_at_jomega(n_re, n_im))
    # sin² + cos² = 1
    return sp.expand(F.subs(sp.sin(delta * omega) ** 2, 1 - sp.cos(delta * omega) ** 2))


@cache
def margin_series(omega_order: int = 6, delay_order: int | None = None) -> sp.Expr:
    """Taylor series of F(ω) = |D(jω)|² − |N(jω)|² in ω, truncated at ω^omega_order.

    Parameters
    ----------
    omega_order : int, default 6
        Highest power of ω kept (even, ≥ 2).  Proposition 1 uses 6.
    delay_order : int or None, default None
        ``None`` expands the exact delay e^{−δjω} (cos and sin) in ω.  An integer
        first replaces e^{−δs} by its Taylor polynomial of that order, as a
        Padé-free *Taylor approximation of the delay*.  The paper's printed Ψ1
        corresponds to ``delay_order=3``: it lacks the δ⁴ term k_x k_a δ⁴/12 of
        the exact series.

    Returns
    -------
    sympy.Expr
        Polynomial in ω (even powers only).
    """
    if omega_order < 2 or omega_order % 2:
        raise StringStabError(f"omega_order must be an even integer >= 2; got {omega_order!r}")
    if delay_order is None:
        F = margin_exact()
        ser = sp.series(F, omega, 0, omega_order + 1).removeO()
        return sp.expand(ser)
    if delay_order < 0:
        raise StringStabError(f"delay_order must be >= 0 or None; got {delay_order!r}")
    g = gamma()
    n0, n1 = delay_parts(g.numerator)
    taylor = sum((-delta * s) ** k / sp.factorial(k) for k in range(delay_order + 1))
    jw = sp.I * omega
    n = sp.expand((n0 + n1 * taylor).subs(s, jw))
    d = sp.expand(g.denominator.subs(s, jw))
    F = _abs2_at_jomega(*d.as_real_imag()) - _abs2_at_jomega(*n.as_real_imag())
    poly = sp.Poly(sp.expand(F), omega)
    return sp.expand(
        sum(c * omega**k for (k,), c in poly.terms() if k <= omega_order)
    )


@cache
def margin_coefficients(
    omega_order: int = 6, delay_order: int | None = None
) -> dict[int, sp.Expr]:
    """Coefficients c_k of ω^k in :func:`margin_series` (k = 2, 4, …, omega_order).

    The ω⁰ coefficient vanishes identically (Γ(0) = 1) and odd ones are zero.

    Parameters
    ----------
    omega_order : int
        Highest power of ω kept (even, ≥ 2); see :func:`margin_series`.
    delay_order : int or None
        ``None``: exact delay; an integer: Taylor polynomial of e^{−δs} of that order
        (see :func:`margin_series`).

    Returns
    -------
    dict of int to sympy.Expr
        ``{k: c_k}`` for k = 2, 4, …, ``omega_order``, in the gains and τ, δ, T*.

    Examples
    --------
    >>> c = margin_coefficients()
    >>> sorted(c)
    [2, 4, 6]
    >>> sp.factor(c[2])
    k_x*(headway**2*k_x + 2*headway*k_v + 2*k_a - 2)
    """
    ser = margin_series(omega_order, delay_order)
    poly = sp.Poly(ser, omega)
    out = {k: sp.expand(poly.coeff_monomial(omega**k)) for k in range(2, omega_order + 1, 2)}
    const = sp.simplify(poly.coeff_monomial(1))
    if const != 0:  # pragma: no cover - a property of the model, asserted in tests
        raise AssertionError(f"ω⁰ coefficient should vanish; got {const}")
    return out


def derived_psi(delay_order: int | None = None) -> tuple[sp.Expr, sp.Expr, sp.Expr, sp.Expr]:
    """Ψ1, Ψ2, Ψ3 and Λ = Ψ2² − 4Ψ1Ψ3 derived from the model (IDL eqs 12-15).

    Dividing the ω⁶-truncated margin by ω² gives Ψ1 ω⁴ + Ψ2 ω² + Ψ3, so Ψ1, Ψ2
    and Ψ3 are the ω⁶, ω⁴ and ω² coefficients of F(ω).

    Parameters
    ----------
    delay_order : int or None
        See :func:`margin_series`; ``None`` (exact delay) by default, ``3`` gives
        the truncation of the printed forms.

    Returns
    -------
    tuple of sympy.Expr
        (Ψ1, Ψ2, Ψ3, Λ).

    Examples
    --------
    >>> psi1, psi2, psi3, lam = derived_psi()
    >>> psi1
    delta**4*k_a*k_x/12 + delta**3*k_a*k_v/3 + tau**2
    """
    c = margin_coefficients(6, delay_order)
    psi1, psi2, psi3 = c[6], c[4], c[2]
    lam = sp.expand(psi2**2 - 4 * psi1 * psi3)
    return psi1, psi2, psi3, lam


def gradients(delay_order: int | None = None) -> dict[str, list[sp.Expr]]:
    """∇_K Ψ2 and ∇_K Ψ3 of the derived Ψ's (IDL eqs 25-26, derived).

    Parameters
    ----------
    delay_order : int or None
        See :func:`margin_series`; ``None`` (exact delay) by default.

    Returns
    -------
    dict
        ``{"grad_psi2": [∂Ψ2/∂k_x, ∂Ψ2/∂k_v, ∂Ψ2/∂k_a], "grad_psi3": [...]}``.
    """
    _, psi2, psi3, _ = derived_psi(delay_order)
    return {
        "grad_psi2": [sp.expand(sp.diff(psi2, k)) for k in GAINS],
        "grad_psi3": [sp.expand(sp.diff(psi3, k)) for k in GAINS],
    }


def routh_hurwitz(poly: sp.Poly) -> list[sp.Expr]:
    """Hurwitz determinants Δ_1 … Δ_n of a polynomial (leading coefficient > 0 assumed).

    Used only when SymPy lacks ``Poly.hurwitz_conditions`` (added after SymPy 1.14);
    it evaluates the definition (leading principal minors of the Hurwitz matrix)
    with SymPy's own determinant, rather than a hand-written Routh table.

    Parameters
    ----------
    poly : sympy.Poly
        The polynomial a_0 sⁿ + a_1 sⁿ⁻¹ + … + a_n (in one generator), a_0 > 0.

    Returns
    -------
    list of sympy.Expr
        The factored determinants Δ_1, …, Δ_n of the leading principal minors of the
        Hurwitz matrix; the polynomial is Hurwitz iff every one is > 0.

    References
    ----------
    A. Hurwitz, "Über die Bedingungen, unter welchen eine Gleichung nur Wurzeln
    mit negativen reellen Theilen besitzt", Math. Ann. 46 (1895) 273-284.
    """
    a = poly.all_coeffs()  # a[0] s^n + a[1] s^{n-1} + ... + a[n]
    n = poly.degree()

    def coef(k: int) -> sp.Expr:
        return a[k] if 0 <= k <= n else sp.Integer(0)

    H = sp.Matrix(n, n, lambda i, j: coef(2 * (j + 1) - (i + 1)))
    return [sp.factor(sp.expand(H[:k, :k].det())) for k in range(1, n + 1)]


@lru_cache(maxsize=1)
def hurwitz_conditions() -> list[sp.Expr]:
    """Internal-stability conditions of Γ's denominator: each expression must be > 0.

    Γ's denominator τs³ + s² + (k_v + T* k_x)s + k_x has no delay, so Γ is
    internally stable iff it is Hurwitz.  Uses ``Poly.hurwitz_conditions`` where
    SymPy provides it, else :func:`routh_hurwitz`; conditions that hold
    identically (such as τ > 0) are dropped, and each determinant is reduced to
    its factors that can change sign.

    Returns
    -------
    list of sympy.Expr
        The conditions, each of which must be > 0.

    Examples
    --------
    >>> hurwitz_conditions()
    [k_x, headway*k_x + k_v - k_x*tau]
    """
    poly = sp.Poly(gamma().denominator, s)
    if hasattr(poly, "hurwitz_conditions"):  # SymPy > 1.14
        raw = list(poly.hurwitz_conditions())
    else:
        raw = [poly.LC(), *routh_hurwitz(poly)]
    conds: list[sp.Expr] = []
    for c in raw:
        # keep the factors that can be non-positive; positive symbols (tau) and
        # already-listed factors are implied by earlier conditions
        _coeff, factors = sp.factor_list(sp.expand(c))
        for f, _mult in factors:
            f = sp.expand(f)
            if f.is_positive or any(sp.expand(f - g) == 0 for g in conds):
                continue
            conds.append(f)
    # a product condition Δ_n = a_0 Δ_{n-1} > 0 is implied by the factors kept
    return sorted(conds, key=lambda e: (len(str(e)), str(e)))


Source = str  # "derived" or "printed"


@cache
def lambdify_psi(
    source: Source = "derived", delay_order: int | None = None
) -> Callable[..., tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]:
    """NumPy functions for (Ψ1, Ψ2, Ψ3, Λ) from the derived or the printed forms.

    Parameters
    ----------
    source : {"derived", "printed"}
        ``"derived"``: :func:`derived_psi` (exact-delay series); ``"printed"``:
        the IDL paper's eqs 12-15 as printed (:mod:`stringstab.derive.printed`).
    delay_order : int or None
        Only for ``"derived"``; see :func:`margin_series`.  ``None`` and the
        printed forms use the code generated from these expressions
        (:mod:`stringstab.derive.generated`, as :func:`stringstab.certify.criteria.psi`
        evaluates it); other orders are lambdified here.

    Returns
    -------
    callable
        ``f(k_x, k_v, k_a, tau, delta, headway) -> (psi1, psi2, psi3, lam)``,
        vectorised with NumPy broadcasting.

    Examples
    --------
    >>> f = lambdify_psi("derived")
    >>> [round(float(v), 6) for v in f(1.0, 0.5, 0.2, 0.1, 0.2, 1.1)]
    [0.010293, 0.592, 0.71, 0.321231]
    """
    if source not in ("derived", "printed"):
        raise StringStabError(f"source must be 'derived' or 'printed'; got {source!r}")
    if source == "printed" or delay_order is None:
        # the generated code of these two (stringstab.derive.generated, tested against SymPy),
        # evaluated as stringstab.certify.criteria.psi does (float inputs, broadcast outputs)
        from . import generated

        fn = generated.psi_printed if source == "printed" else generated.psi_derived

        def psi(k_x, k_v, k_a, tau, delta, headway):  # type: ignore[no-untyped-def]
            args = (k_x, k_v, k_a, tau, delta, headway)
            shape = np.broadcast_shapes(*(np.shape(v) for v in args))
            p1, p2, p3 = (np.broadcast_to(np.asarray(o, dtype=float), shape)
                          for o in fn(*(np.asarray(v, dtype=float) for v in args)))
            return p1, p2, p3, p2 * p2 - 4.0 * p1 * p3

        psi.__doc__ = f"(Ψ1, Ψ2, Ψ3, Λ) from the {source} forms (generated code)."
        return psi
    exprs = derived_psi(delay_order)
    # Ψ1-Ψ3 are low-degree polynomials; Λ is evaluated from them by its
    # definition Ψ2² − 4Ψ1Ψ3 (eq 15) rather than from its expanded form, which
    # is ~4x slower in NumPy (integer powers) and no more accurate.
    lam = sp.lambdify([*GAINS, *PARAMS], list(exprs[:3]), modules="numpy", cse=True)

    def psi_n(k_x, k_v, k_a, tau, delta, headway):  # type: ignore[no-untyped-def]
        shape = np.broadcast_shapes(*(np.shape(v) for v in (k_x, k_v, k_a, tau, delta, headway)))
        p1, p2, p3 = (np.broadcast_to(np.asarray(o, dtype=float), shape)
                      for o in lam(k_x, k_v, k_a, tau, delta, headway))
        return p1, p2, p3, p2 * p2 - 4.0 * p1 * p3

    psi_n.__doc__ = f"(Ψ1, Ψ2, Ψ3, Λ) from the derived forms, delay order {delay_order}."
    return psi_n


#: Names a caller may substitute with :func:`derive_all` (everything but s and ω).
SUBSTITUTABLE: dict[str, sp.Symbol] = {str(x): x for x in (*GAINS, *PARAMS)}


def parse_substitutions(text: str | None,
                        allowed: dict[str, sp.Symbol] | None = None) -> dict[sp.Symbol, sp.Expr]:
    """Parse ``"tau=0.1,delta=0.2,headway=1.1"`` into exact SymPy rationals.

    ``allowed`` names the substitutable symbols (default :data:`SUBSTITUTABLE`; the sampled
    derivation adds ``tau_prev``).

    Parameters
    ----------
    text : str or None
        Comma-separated ``NAME=VALUE`` pairs; ``None`` or ``""`` gives no substitution.
    allowed : dict of str to sympy.Symbol, optional
        The names that may be substituted (default :data:`SUBSTITUTABLE`).

    Returns
    -------
    dict of sympy.Symbol to sympy.Expr
        Each symbol mapped to the exact rational of its value.

    Raises
    ------
    StringStabError
        On an unknown name, a malformed pair, a non-finite value, or τ ≤ 0,
        δ < 0, T* < 0.

    Examples
    --------
    >>> parse_substitutions("tau=0.1,delta=0.2")
    {tau: 1/10, delta: 1/5}
    """
    from ..errors import StringStabError

    out: dict[sp.Symbol, sp.Expr] = {}
    names = SUBSTITUTABLE if allowed is None else allowed
    if not text:
        return out
    for item in text.split(","):
        item = item.strip()
        if not item:
            continue
        name, sep, value = item.partition("=")
        name = name.strip()
        if not sep:
            raise StringStabError(f"--substitute expects NAME=VALUE pairs; got {item!r}")
        if name not in names:
            raise StringStabError(
                f"--substitute: unknown symbol {name!r}; expected one of {sorted(names)}"
            )
        try:
            v = sp.Rational(value.strip())
        except (TypeError, ValueError) as e:
            raise StringStabError(
                f"--substitute: value of {name} must be a finite number; got {value!r}"
            ) from e
        if name in ("tau", "tau_prev") and not v > 0:
            raise StringStabError(f"{name} (actuator lag) must be > 0 s; got {value!r}")
        if name in ("delta", "headway", "reaction_delay") and v < 0:
            raise StringStabError(f"{name} must be >= 0 s; got {value!r}")
        out[names[name]] = v
    return out


def derive_all(
    delay_order: int | None = None, substitute: dict[sp.Symbol, sp.Expr] | None = None
) -> dict[str, object]:
    """Every derived expression under the stable keys of ``stringstab derive``.

    Keys: ``gamma``, ``gamma_numerator``, ``gamma_denominator``, ``psi1``,
    ``psi2``, ``psi3``, ``lambda``, ``grad_psi2`` and ``grad_psi3`` (lists of
    three), ``hurwitz`` (list of expressions that must each be > 0).

    Parameters
    ----------
    delay_order : int or None
        Taylor order of e^{−δs} for Ψ (None: exact delay); see :func:`margin_series`.
    substitute : dict, optional
        Symbol → value substitutions applied to every expression.

    Returns
    -------
    dict of str to object
        The expressions under the keys listed above.
    """
    sub = substitute or {}
    g = gamma()
    psi1, psi2, psi3, lam = derived_psi(delay_order)
    grads = gradients(delay_order)

    def f(e: sp.Expr) -> sp.Expr:
        return sp.expand(e.subs(sub)) if sub else e

    num = f(g.numerator)
    den = sp.collect(f(g.denominator), s)
    hurwitz: list[sp.Expr] = []
    for c in hurwitz_conditions():
        c2 = f(c)
        if c2.is_number and c2 > 0:
            continue
        hurwitz.append(c2)
    return {
        "gamma": num / den,
        "gamma_numerator": num,
        "gamma_denominator": den,
        "psi1": f(psi1),
        "psi2": f(psi2),
        "psi3": f(psi3),
        "lambda": f(lam),
        "grad_psi2": [f(e) for e in grads["grad_psi2"]],
        "grad_psi3": [f(e) for e in grads["grad_psi3"]],
        "hurwitz": hurwitz,
    }
