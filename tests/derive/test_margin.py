"""The generated numeric code against the SymPy derivation: the one place each form is checked.

Every formula the numeric library evaluates lives in ``stringstab/derive/generated.py``, written by
``python -m stringstab.derive.codegen`` from :mod:`stringstab.derive.symbolic` (and :mod:`stringstab.derive.printed`).
Here each generated form is compared with SymPy's own evaluation of the derived expression (or
of its derivatives), in each back-end it is used with (NumPy arrays, Python floats with the
``math`` module, CasADi symbols), and the committed file with a fresh generation.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from stringstab.certify import margin, quartic_tail
from stringstab.derive import codegen
from stringstab.derive import generated as gen
from stringstab.derive import symbolic as S
from stringstab.derive.printed import printed_psi
from stringstab.tuning import margin_terms

G, P, W = S.GAINS, S.PARAMS, S.omega
ARGS = [*G, *P]
RNG = np.random.default_rng(20240609)
N = 64
KX, KV, KA = RNG.uniform(-2, 2, (3, N))
TAU, DELTA, HEADWAY = RNG.uniform(0.05, 0.6, N), RNG.uniform(0.0, 0.5, N), RNG.uniform(0.3, 2.0, N)
OMEGA = RNG.uniform(0.0, 8.0, N)
POINT = (KX, KV, KA, TAU, DELTA, HEADWAY)
G_EXPR = sp.expand(S.margin_exact() / W**2)


def ref(exprs, *extra):
    """SymPy's values of ``exprs`` at the random points (lambdify of the derivation itself)."""
    f = sp.lambdify([*ARGS, *extra], exprs, "numpy")
    vals = f(*POINT, *([OMEGA] if extra else []))
    return [np.broadcast_to(np.asarray(v, dtype=float), (N,)) for v in vals]


def close(ours, theirs, rtol=1e-10):
    ours = [np.broadcast_to(np.asarray(v, dtype=float), (N,)) for v in ours]
    assert len(ours) == len(theirs)
    for o, t in zip(ours, theirs):
        assert_allclose(o, t, rtol=rtol, atol=rtol * (1.0 + np.max(np.abs(t))))


def test_committed_file_equals_a_fresh_generation():
    assert codegen.TARGET.read_text(encoding="utf-8") == codegen.generate(), (
        "stringstab/derive/generated.py is stale: run `python -m stringstab.derive.codegen`")


def test_the_check_flag_reports_a_stale_file(tmp_path, monkeypatch, capsys):
    stale = tmp_path / "_generated.py"
    stale.write_text("# old\n", encoding="utf-8")
    monkeypatch.setattr(codegen, "TARGET", stale)
    assert codegen.main(["--check"]) == 1
    assert "STALE" in capsys.readouterr().out
    assert stale.read_text(encoding="utf-8") == "# old\n"  # --check never writes


def test_margin_basis_reassembles_the_derived_margin():
    c = codegen.margin_basis()
    d = S.delta
    rebuilt = (c["t2"] * W**4 + c["a"] * W**2 + c["b"] + c["cx"] * sp.cos(d * W)
               - c["cv"] * W * sp.sin(d * W))
    assert sp.expand(rebuilt - G_EXPR) == 0


def test_margin_coefficients_and_their_scales():
    c = codegen.margin_basis()
    names = gen.MARGIN_COEFFICIENTS
    close(gen.margin_coefficients(*POINT), ref([c[n] for n in names]))
    # the scales are Σ |term| of each expanded coefficient, hence ≥ |coefficient|
    terms = [sum(sp.Abs(t) for t in sp.Add.make_args(sp.expand(c[n]))) for n in names]
    scales = gen.margin_coefficient_scales(*POINT)
    close(scales, ref(terms))
    for s_, v in zip(scales, gen.margin_coefficients(*POINT)):
        assert np.all(np.asarray(s_) >= np.abs(v) - 1e-15)


def test_separable_form_reassembles_the_derived_margin():
    """g = (τω² − c)² + h2 ω² + h0 + cx cos δω − cv ω sin δω: symbolically and numerically."""
    c = codegen.margin_separable()
    d, t = S.delta, S.tau
    rebuilt = ((t * W**2 - c["c"]) ** 2 + c["h2"] * W**2 + c["h0"] + c["cx"] * sp.cos(d * W)
               - c["cv"] * W * sp.sin(d * W))
    assert sp.expand(rebuilt - G_EXPR) == 0
    (cc, h2, h0, cx, cv), scales = margin.separable(KX, KV, KA, headway=HEADWAY)
    close([cc, h2, h0, cx, cv], ref(list(c.values())))
    for s_, v in zip(scales, (cc, h2, h0, cx, cv)):
        assert np.all(np.asarray(s_) >= np.abs(v) - 1e-15)


def test_margin_g_in_every_form():
    expect = ref([G_EXPR], W)
    close([gen.margin_g(OMEGA, *POINT)], expect)
    close([margin.g(OMEGA, KX, KV, KA, tau=TAU, delta=DELTA, headway=HEADWAY)], expect)
    co = margin.coefficients(KX, KV, KA, tau=TAU, delta=DELTA, headway=HEADWAY)
    close([margin.g_from_coefficients(OMEGA, co, DELTA)], expect)
    sc = margin.coefficient_scales(KX, KV, KA, tau=TAU, delta=DELTA, headway=HEADWAY)
    gv, scale = margin.g_and_scale(OMEGA, co, sc, DELTA)
    close([gv], expect)
    assert np.all(scale >= np.abs(gv))
    # scalar (math module) and CasADi forms give the same numbers
    scalar = [gen.margin_g(*(float(a[i]) for a in (OMEGA, *POINT)), math.cos, math.sin)
              for i in range(N)]
    close([np.array(scalar)], expect)


def test_casadi_form_of_g():
    casadi = pytest.importorskip("casadi")
    K = casadi.SX.sym("K", 3)
    x = casadi.SX.sym("x", 4)  # ω, τ, δ, T*
    (e,) = margin_terms.casadi_g([x[0]], K[0], K[1], K[2], x[1], x[2], x[3])
    f = casadi.Function("g", [K, x], [e])
    vals = [float(f([KX[i], KV[i], KA[i]], [OMEGA[i], TAU[i], DELTA[i], HEADWAY[i]]))
            for i in range(N)]
    close([np.array(vals)], ref([G_EXPR], W))


def test_gradient_and_newton_terms_are_sympys_derivatives():
    dK = [sp.diff(G_EXPR, k) for k in G]
    gw = sp.diff(G_EXPR, W)
    hess = [sp.diff(G_EXPR, G[i], G[j]) for i in range(3) for j in range(i, 3)]
    expect = ref([G_EXPR, *dK, gw, *(sp.diff(gw, k) for k in G), sp.diff(gw, W), *hess], W)
    close(gen.margin_gradient(OMEGA, *POINT), expect[:4])
    close(gen.margin_newton(OMEGA, *POINT), expect)
    for i in range(0, N, 7):  # the scalar wrappers of margin.py
        gv, gk, gwv, gwk, gww, gkk = margin_terms.newton_terms(
            float(OMEGA[i]), float(KX[i]), float(KV[i]), float(KA[i]),
            float(TAU[i]), float(DELTA[i]), float(HEADWAY[i]))
        flat = np.array([gv, *gk, gwv, *gwk, gww, *gkk[np.triu_indices(3)]])
        want = np.array([e[i] for e in expect])
        assert_allclose(flat, want, rtol=1e-10, atol=1e-10 * (1 + np.max(np.abs(want))))
        assert_allclose(gkk, gkk.T, rtol=0, atol=0)
        _, grad = margin_terms.gradient(OMEGA[i:i + 3], [KX[i], KV[i], KA[i]],
                                  tau=TAU[i], delta=DELTA[i], headway=HEADWAY[i])
        assert grad.shape == (min(3, N - i), 3)
        assert_allclose(grad[0], want[1:4], rtol=1e-10, atol=1e-10 * (1 + np.max(np.abs(want))))


def test_psi_derived_and_printed():
    close(gen.psi_derived(*POINT), ref(list(S.derived_psi()[:3])))
    close(gen.psi_printed(*POINT), ref(list(printed_psi()[:3])))


@pytest.mark.parametrize("source", ["derived", "printed"])
@pytest.mark.parametrize("gain", ["k_x", "k_v", "k_a"])
def test_psi_polynomials(source, gain):
    exprs = S.derived_psi() if source == "derived" else printed_psi()
    g0 = dict(zip(("k_x", "k_v", "k_a"), G))[gain]
    values = dict(zip(("k_x", "k_v", "k_a"), (KX, KV, KA)))
    others = {k: v for k, v in values.items() if k != gain}
    polys = gen.psi_polynomials(source, gain, **others, tau=TAU, delta=DELTA, headway=HEADWAY)
    for e, coeffs in zip(exprs, polys):
        want = sp.Poly(sp.expand(e), g0).all_coeffs()
        assert len(coeffs) == len(want)
        close(coeffs, ref(want))
    # and evaluated as polynomials they are Ψ1, Ψ2, Ψ3, Λ
    x = values[gain]
    got = [sum(np.asarray(c) * x ** (len(cs) - 1 - k) for k, c in enumerate(cs)) for cs in polys]
    close(got, ref(list(exprs)))


def test_hurwitz_conditions_scales_and_gradients():
    conds = S.hurwitz_conditions()
    close(gen.hurwitz_conditions(*POINT), ref(conds))
    grads = [sp.diff(c, k) for c in conds for k in G]
    close(gen.hurwitz_gradients(TAU, DELTA, HEADWAY), ref(grads))
    for s_, c in zip(gen.hurwitz_scales(*POINT), gen.hurwitz_conditions(*POINT)):
        assert np.all(np.asarray(s_) >= np.abs(c))


def test_gamma_parts_and_polynomial_coefficients():
    gam = S.gamma()
    N_jw = sp.lambdify([*ARGS, S.s], gam.numerator, "numpy")
    D_jw = sp.lambdify([*ARGS, S.s], gam.denominator, "numpy")
    n = N_jw(*POINT, 1j * OMEGA)
    d = D_jw(*POINT, 1j * OMEGA)
    close(gen.gamma_parts(OMEGA, *POINT), [n.real, n.imag, d.real, d.imag])
    close(gen.denominator_coefficients(*POINT), ref(sp.Poly(gam.denominator, S.s).all_coeffs()))
    n0, n1 = S.delay_parts(gam.numerator)
    co = gen.numerator_coefficients(*POINT)
    k = gen.NUMERATOR_SPLIT
    close(co[:k], ref(sp.Poly(n0, S.s).all_coeffs()))
    close(co[k:], ref(sp.Poly(n1, S.s).all_coeffs()))
    p = gen.denominator_abs2_coefficients(*POINT)
    x = OMEGA**2
    close([sum(np.asarray(c) * x ** (len(p) - 1 - i) for i, c in enumerate(p))], [np.abs(d) ** 2])


@settings(max_examples=60, deadline=None)
@given(kx=st.floats(-2, 2), kv=st.floats(-2, 2), ka=st.floats(-2, 2), tau=st.floats(0.05, 1.0),
       delta=st.floats(0.0, 0.5), headway=st.floats(0.3, 2.5), r=st.floats(0.01, 30.0))
def test_curvature_bound_bounds_the_second_derivative(kx, kv, ka, tau, delta, headway, r):
    """M(r) ≥ |g''(ω)| on [0, r], checked on a fine grid with SymPy's g''."""
    g2 = _G2(kx, kv, ka, tau, delta, headway, np.linspace(0.0, r, 2001))
    co = margin.coefficients(kx, kv, ka, tau=tau, delta=delta, headway=headway)
    M = float(margin.curvature_bound(r, co, delta))
    assert np.max(np.abs(g2)) <= M * (1 + 1e-12) + 1e-12


_G2 = sp.lambdify([*ARGS, W], sp.diff(G_EXPR, W, 2), "numpy")


@settings(max_examples=60, deadline=None)
@given(kx=st.floats(-2, 2), kv=st.floats(-2, 2), ka=st.floats(-2, 2), tau=st.floats(0.05, 1.0),
       delta=st.floats(0.0, 0.5), headway=st.floats(0.3, 2.5))
def test_tail_bound_and_fujiwara_bound(kx, kv, ka, tau, delta, headway):
    """g > 0 beyond Ω (a dense sweep of SymPy's g), and Ω ≤ Fujiwara's bound (+ its floor)."""
    co = margin.coefficients(kx, kv, ka, tau=tau, delta=delta, headway=headway)
    Om = float(margin.tail_bound(*co))
    gf = sp.lambdify([*ARGS, W], G_EXPR, "numpy")
    w = np.linspace(Om, 20 * Om + 10, 20_000)[1:]
    assert np.all(gf(kx, kv, ka, tau, delta, headway, w) > 0)
    A, B, C = margin.tail_coefficients(*co)
    assert Om <= max(float(quartic_tail.fujiwara_bound(A, B, C)), 1e-3) * (1 + 1e-8) + 1e-11


def _vectorised_tail_bound(A, B, C, monkeypatch):
    """quartic_tail_bound's numpy path, whatever the batch size."""
    monkeypatch.setattr(quartic_tail, "SMALL_TAIL_BATCH", -1)
    try:
        return quartic_tail.quartic_tail_bound(A, B, C)
    finally:
        monkeypatch.undo()


@pytest.mark.parametrize("n", [1, 2, 5, 8])
def test_small_quartic_tail_bound_is_the_vectorised_one_bit_for_bit(n, monkeypatch):
    """The Python-float path of a few quartics returns the numpy path's bits (and is a bound).

    The inputs: random coefficients over many magnitudes, zeros (the floor 1e-3), and the
    (A, B, C) of random gains of the Table-2 box; the numpy path on the same batch (the same
    stopping step) is the reference.
    """
    rng = np.random.default_rng(n)
    for trial in range(300):
        if trial % 3 == 0:
            K = rng.uniform(-2, 2, (n, 3))
            co = margin.coefficients(K[:, 0], K[:, 1], K[:, 2], tau=0.1, delta=0.2, headway=1.1)
            A, B, C = margin.tail_coefficients(*co)
        else:
            A, B, C = (10.0 ** rng.uniform(-12, 6, n) * (rng.random(n) < 0.8) for _ in range(3))
        small = quartic_tail.quartic_tail_bound(A, B, C)
        ref = _vectorised_tail_bound(A, B, C, monkeypatch)
        assert small.shape == ref.shape and small.tobytes() == ref.tobytes()
        L = ((small**2 - A) * small - B) * small - C
        assert np.all((L > 0) | ((A == 0) & (B == 0) & (C == 0)))
    # a 0-d input stays 0-d
    assert quartic_tail.quartic_tail_bound(4.0, 0.0, 0.0).shape == ()


def test_local_minima_finds_the_dip_a_sweep_finds():
    K = (0.9, -0.5, 1.1)
    gmin, dips = margin.local_minima(K, tau=0.1, delta=0.2, headway=1.1, threshold=0.0)
    w = np.linspace(0.0, 20.0, 400_001)
    gv = margin.g(w, *K, tau=0.1, delta=0.2, headway=1.1)
    assert len(dips) == 1
    assert_allclose(dips[0], w[np.argmin(gv)], atol=1e-4)
    assert_allclose(gmin, gv.min(), rtol=1e-6)
    assert margin.local_minima((1.5, 0.3, -0.1), tau=0.1, delta=0.2, headway=1.1,
                               threshold=0.0)[1] == []
