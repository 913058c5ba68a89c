"""An independent check of the certificate with a reaction delay θ_r (issue 25, item 6).

Nothing here is used inside the certificate.  For each case (K, τ, δ, T*, θ_r) it computes,
from scratch:

(a) **stability** from a Chebyshev pseudospectral discretisation of the delay equation's
    infinitesimal generator (Breda, Maset, Vermiglio 2005): the DDE
    τy''' + y'' + c y'(t − θ_r) + k_x y(t − θ_r) = 0 (characteristic function
    τs³ + s² + e^{−θ_r s}(cs + k_x), c = k_v + T*k_x) as x' = A0 x + A1 x(t − θ_r), its
    generator discretised on N + 1 Chebyshev nodes of [−θ_r, 0]; the rightmost eigenvalue
    converges spectrally as N grows (N = 16 and N = 24 are both computed — on 300 seeded
    cases both agree with N = 48 to 5e-10 — and a case whose two disagree by more than 1e-6
    is "unresolved" and left out of the comparison);
(b) **a second stability check**: the roots of the polynomial τs³ + s² + R(s)(cs + k_x) with
    R the Padé(12, 12) approximant of e^{−θ_r s} (times its denominator), counted in Re s > 0;
(c) **sup|Γ(jω)|** by a dense sweep of the exact Γ(jω) (e^{−jθ_rω}, e^{−jδω} evaluated
    directly as complex exponentials) on [10⁻⁴, ω_hi], ω_hi the root of
    τω³ − |k_a|ω² − (|c| + |k_v|)ω − 2|k_x| (beyond it |N(jω)| < |D(jω)|: |N| ≤ |k_x| +
    |k_v|ω + |k_a|ω², |D| ≥ τω³ − |c|ω − |k_x|), 3,000 points (linear and logarithmic), the
    largest local maxima refined; and the normalised margin min (1 − |Γ|²)/min(1, ω²).

and compares with ``stringstab.certify_batch(..., reaction_delay=θ_r)``:

* **unsound**: ``certified`` while (a) finds a root with Re s > 10⁻⁶ or (c) a gain above
  1 + 10⁻⁹; ``not_certified`` while (a) says stable (Re < −10⁻⁶), (c) says |Γ| ≤ 1 (margin >
  10⁻⁶) and the certificate's witness does not hold either; or a claimed witness does not hold
  (the stated root count ≥ 1 against (a); |Γ(jω)| at the reported peak ≤ 1, evaluated in double
  precision or, where the excess is below 10⁻⁹, in 40-digit arithmetic with mpmath — a Ψ3 just
  below 0 puts excesses of 10⁻¹⁸ at ω ~ 10⁻⁵, which the sweep cannot see); must be 0.
* **root counts**: the certificate's ``unstable_roots`` against (a) and (b) away from the
  boundary;
* **conservatism**: the share ``inconclusive`` and how close those cases are to a boundary.

Cases: random K in the IDL range [−2, 2]³ and in [−5, 5]³, τ ∈ [0.05, 1], δ ∈ [0, 1],
T* ∈ [0, 3], θ_r ∈ (0, 1] (and, where more are certified, K ∈ [0, 0.6] × [0, 1.5] × [−1, 1]
with T* ∈ 2(τ + θ_r) + [0.5, 3] s); cases *on* the stability boundary (D(jω₀) = 0 solved for
k_x and c at a random ω₀, exact), perturbed by 0, ±10⁻⁹, ±10⁻⁶, ±10⁻³; on Ψ3 = 0 (the |Γ| = 1 boundary
at ω → 0); and on the |Γ| = 1 boundary at a positive frequency, by bisection of k_a between a
certified and a not-certified value (these two with T* ∈ 2(τ + θ_r) + [0.5, 3] s and
small positive k_x, k_v, where certified gains exist).

    python analysis/reaction_check.py --n 100000 --seed 0        # the closing figures
    python analysis/reaction_check.py --n 2000                   # a quick look

``tests/certify/test_reaction_check.py`` runs a seeded few hundred cases of the same code.

References
----------
D. Breda, S. Maset, R. Vermiglio, "Pseudospectral differencing methods for characteristic
roots of delay differential equations", SIAM J. Sci. Comput. 27 (2005) 482-495.
L. N. Trefethen, *Spectral Methods in MATLAB*, SIAM 2000 (``cheb``).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from typing import Any

# one BLAS thread per process: the batched eigenvalue problems are many and small
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np

import stringstab as ss

#: Cases whose two spectral resolutions differ by more than this are left out (unresolved).
RESOLVED = 1e-6
#: Away from the stability boundary: |rightmost Re| above this.
STAB_TOL = 1e-6
#: Away from the |Γ| = 1 boundary: normalised margin beyond ±this (and gain above 1 + GAIN_TOL).
GAIN_TOL = 1e-6


# --------------------------------------------------------------------------- (a) spectral
def _cheb(N: int) -> tuple[np.ndarray, np.ndarray]:
    """Trefethen's Chebyshev differentiation matrix and nodes on [−1, 1] (x_0 = 1)."""
    x = np.cos(np.pi * np.arange(N + 1) / N)
    c = np.hstack([2.0, np.ones(N - 1), 2.0]) * (-1.0) ** np.arange(N + 1)
    X = np.tile(x, (N + 1, 1)).T
    dX = X - X.T
    D = np.outer(c, 1.0 / c) / (dX + np.eye(N + 1))
    D -= np.diag(D.sum(axis=1))
    return D, x


def spectral_eigenvalues(kx, kv, tau, headway, theta, N: int = 32) -> np.ndarray:
    """Eigenvalues of the pseudospectral generator, one row per case (batched)."""
    kx, kv, tau, headway, theta = np.broadcast_arrays(*(np.asarray(v, float) for v in
                                                        (kx, kv, tau, headway, theta)))
    n = kx.size
    c = kv + headway * kx
    D, _ = _cheb(N)
    base = np.kron(D, np.eye(3))  # nodes t_j = θ(x_j − 1)/2: d/dt = (2/θ) d/dx
    d = 3 * (N + 1)
    out = np.empty((n, d), dtype=complex)
    for s0 in range(0, n, 200):
        sl = slice(s0, min(s0 + 200, n))
        b = sl.stop - sl.start
        M = base[None, :, :] * (2.0 / theta[sl])[:, None, None]
        M[:, :3, :] = 0.0
        M[:, 0, 1] = 1.0
        M[:, 1, 2] = 1.0
        M[:, 2, 2] = -1.0 / tau[sl]
        M[:, 2, d - 3] = -kx[sl] / tau[sl]
        M[:, 2, d - 2] = -c[sl] / tau[sl]
        out[sl] = np.linalg.eigvals(M) if b else out[sl]
    return out


def spectral_rightmost(kx, kv, tau, headway, theta
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(rightmost Re at N = 24, |difference to N = 16|, roots with Re > 0, a root near the axis).

    The count is of the N = 24 eigenvalues with Re > STAB_TOL; "near the axis" when some
    eigenvalue has |Re| ≤ STAB_TOL (the count is then not compared).
    """
    e1 = spectral_eigenvalues(kx, kv, tau, headway, theta, 16)
    e2 = spectral_eigenvalues(kx, kv, tau, headway, theta, 24)
    r1, r2 = e1.real.max(axis=1), e2.real.max(axis=1)
    cnt = np.sum(e2.real > STAB_TOL, axis=1)
    near = np.any(np.abs(e2.real) <= STAB_TOL, axis=1)
    return r2, np.abs(r2 - r1), cnt, near


# --------------------------------------------------------------------------- (b) Padé
def pade_count(kx, kv, tau, headway, theta, m: int = 12) -> tuple[np.ndarray, np.ndarray]:
    """(roots with Re > STAB_TOL, a root with |Re| ≤ STAB_TOL) of τs³ + s² + R_m(s)(cs + k_x).

    R_m is the Padé(m, m) approximant of e^{−θ_r s}; the polynomial is D times R_m's denominator.
    """
    kx, kv, tau, headway, theta = np.broadcast_arrays(*(np.asarray(v, float) for v in
                                                        (kx, kv, tau, headway, theta)))
    f = math.factorial
    a = np.array([f(2 * m - k) * f(m) / (f(2 * m) * f(k) * f(m - k)) for k in range(m + 1)])
    k = np.arange(m + 1)
    den = a[None, :] * theta[:, None] ** k[None, :]
    num = den * (-1.0) ** k[None, :]
    c = kv + headway * kx
    deg = m + 3
    p = np.zeros((kx.size, deg + 1))
    p[:, 2:m + 3] += den
    p[:, 3:m + 4] += tau[:, None] * den
    p[:, 0:m + 1] += kx[:, None] * num
    p[:, 1:m + 2] += c[:, None] * num
    C = np.zeros((kx.size, deg, deg))
    C[:, 0, :] = -p[:, -2::-1] / p[:, -1:]
    C[:, np.arange(1, deg), np.arange(deg - 1)] = 1.0
    ev = np.linalg.eigvals(C)
    return np.sum(ev.real > STAB_TOL, axis=1), np.any(np.abs(ev.real) <= STAB_TOL, axis=1)


# --------------------------------------------------------------------------- (c) sweep
def gamma(w, kx, kv, ka, tau, delta, headway, theta) -> np.ndarray:
    """Γ(jω) evaluated directly (complex exponentials; not the toolkit's generated code)."""
    s = 1j * w
    er, ed = np.exp(-theta * s), np.exp(-delta * s)
    c = kv + headway * kx
    return er * (kx + kv * s + ka * s * s * ed) / (tau * s**3 + s * s + er * (c * s + kx))


def sweep(kx, kv, ka, tau, delta, headway, theta, n: int = 3000) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(sup |Γ(jω)| found, where, min over ω of (1 − |Γ|²)/min(1, ω²)) per case."""
    args = np.broadcast_arrays(*(np.asarray(v, float) for v in
                                 (kx, kv, ka, tau, delta, headway, theta)))
    kx, kv, ka, tau, delta, headway, theta = args
    c = kv + headway * kx
    m = kx.size
    hi = np.empty(m)
    for i in range(m):
        r = np.roots([tau[i], -abs(ka[i]), -(abs(c[i]) + abs(kv[i])), -2 * abs(kx[i])])
        hi[i] = max(float(np.max(r[np.abs(r.imag) < 1e-9].real, initial=0.0)) * 1.05, 1.0)
    u = np.linspace(0.0, 1.0, n // 2)
    lg = np.logspace(-4, 0, n - n // 2)
    sup, arg, marg = np.empty(m), np.empty(m), np.empty(m)
    for s0 in range(0, m, 256):
        sl = slice(s0, min(s0 + 256, m))
        W = np.concatenate([hi[sl, None] * u[None, :], hi[sl, None] * lg[None, :]], axis=1)
        W = np.sort(np.maximum(W, 1e-4), axis=1)
        col = [v[sl, None] for v in args]
        G = np.abs(gamma(W, *col))
        G = np.where(np.isfinite(G), G, np.inf)
        # refine around the three largest local maxima
        best = G.max(axis=1)
        bw = W[np.arange(W.shape[0]), np.argmax(G, axis=1)]
        left = np.concatenate([np.full((G.shape[0], 1), -np.inf), G[:, :-1]], axis=1)
        right = np.concatenate([G[:, 1:], np.full((G.shape[0], 1), -np.inf)], axis=1)
        loc = np.where((G >= left) & (G >= right), G, -np.inf)
        top = np.argsort(-loc, axis=1)[:, :3]
        for j in range(3):
            idx = top[:, j]
            rows = np.arange(W.shape[0])
            cen = W[rows, idx]
            half = np.maximum(np.abs(W[rows, np.minimum(idx + 1, W.shape[1] - 1)]
                                     - W[rows, np.maximum(idx - 1, 0)]), 1e-9)
            for _ in range(10):
                Wl = np.maximum(cen[:, None] + half[:, None] * np.linspace(-1, 1, 11)[None, :], 1e-4)
                Gl = np.abs(gamma(Wl, *col))
                Gl = np.where(np.isfinite(Gl), Gl, np.inf)
                k = np.argmax(Gl, axis=1)
                cen = Wl[rows, k]
                half = half / 5.0
                better = Gl[rows, k] > best
                best = np.where(better, Gl[rows, k], best)
                bw = np.where(better, cen, bw)
        sup[sl], arg[sl] = best, bw
        with np.errstate(invalid="ignore"):
            marg[sl] = np.nanmin((1.0 - G * G) / np.minimum(1.0, W * W), axis=1)
    return sup, arg, marg


# --------------------------------------------------------------------------- cases
#: Cases per parameter set (τ, δ, T*, θ_r drawn once per set; the certificate runs per set).
GROUP = 50


def cases(n: int, seed: int) -> dict[str, np.ndarray]:
    """The seeded cases: random, on/near the stability boundary, on/near |Γ| = 1.

    Parameter sets (τ, δ, T*, θ_r) are drawn at random; each holds :data:`GROUP` cases.
    """
    rng = np.random.default_rng(seed)
    shares = {"random": 0.4, "random, large T*": 0.1, "stability boundary": 0.2, "psi3 = 0": 0.1,
              "|Γ| = 1 by bisection": 0.2}
    out: dict[str, list] = {k: [] for k in ("kind", "group", "k_x", "k_v", "k_a", "tau", "delta",
                                           "headway", "theta")}
    group = 0
    for kind, share in shares.items():
        for _ in range(max(1, round(n * share / GROUP))):
            tau, delta = rng.uniform(0.05, 1.0), rng.uniform(0.0, 1.0)
            headway, theta = rng.uniform(0.0, 3.0), 1.0 - rng.uniform(0.0, 1.0)  # θ_r ∈ (0, 1]
            if kind in ("random, large T*", "psi3 = 0", "|Γ| = 1 by bisection"):  # certifiable
                headway = 2.0 * (tau + theta) + rng.uniform(0.5, 3.0)
            K = _group(kind, rng, tau, delta, headway, theta)
            out["kind"] += [kind] * len(K)
            out["group"] += [group] * len(K)
            for j, name in enumerate(("k_x", "k_v", "k_a")):
                out[name] += list(K[:, j])
            for name, v in (("tau", tau), ("delta", delta), ("headway", headway), ("theta", theta)):
                out[name] += [v] * len(K)
            group += 1
    return {k: np.array(v) for k, v in out.items()}


def _group(kind: str, rng: np.random.Generator, tau: float, delta: float, headway: float,
           theta: float) -> np.ndarray:
    g = GROUP
    eps = np.array([0.0, 1e-9, -1e-9, 1e-6, -1e-6, 1e-3, -1e-3])
    if kind == "random":  # the IDL range, and 30 % of the sets 2.5 times wider
        return rng.uniform(-2, 2, (g, 3)) * (2.5 if rng.random() < 0.3 else 1.0)
    if kind == "random, large T*":  # small positive k_x, k_v
        return rng.uniform([0.0, 0.0, -1.0], [0.6, 1.5, 1.0], (g, 3))
    if kind == "stability boundary":  # D(jω0) = 0 solved for (k_x, c), then perturbed
        w0 = np.exp(rng.uniform(np.log(0.05), np.log(5.0), g))
        z = (w0**2 + 1j * tau * w0**3) * np.exp(1j * theta * w0)
        e = rng.choice(eps, g)
        kx = z.real * (1 + e)
        c = z.imag / w0 * (1 + e * rng.choice([-1.0, 1.0], g))
        return np.stack([kx, c - headway * kx, rng.uniform(-2, 2, g)], axis=1)
    if kind == "psi3 = 0":  # k_a = 1 − (k_xT*² + 2k_vT*)/2, perturbed
        kx, kv = rng.uniform(0.01, 0.6, g), rng.uniform(0.05, 1.5, g)
        ka = 1 - (kx * headway**2 + 2 * kv * headway) / 2 + rng.choice(eps, g)
        return np.stack([kx, kv, ka], axis=1)
    # |Γ| = 1 at a positive frequency: bisection of k_a between certified and not certified
    kx, kv = rng.uniform(0.01, 0.6, g), rng.uniform(0.05, 1.5, g)
    P = dict(tau=tau, delta=delta, headway=headway, reaction_delay=theta)
    scan = np.linspace(-1.0, 1.5, 11)
    ok = np.stack([ss.check(kx, kv, np.full(g, a), **P).verdict == "certified" for a in scan], axis=1)
    good = ok.any(axis=1)
    j = np.where(good, 10 - np.argmax(ok[:, ::-1], axis=1), 0)  # the largest certified k_a
    lo = scan[j]
    hi = np.where(j < 10, scan[np.minimum(j + 1, 10)], 3.0)
    for _ in range(30):
        mid = 0.5 * (lo + hi)
        ok = ss.check(kx, kv, mid, **P).verdict == "certified"
        lo, hi = np.where(ok, mid, lo), np.where(ok, hi, mid)
    ka = np.where(rng.random(g) < 0.5, lo, hi)
    ka = np.where(good, ka, rng.uniform(-2, 2, g))  # no certified k_a: a random one
    return np.stack([kx, kv, ka], axis=1)


# --------------------------------------------------------------------------- comparison
def certify_cases(c: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """The certificate, one ``certify_batch`` per parameter set."""
    keys = ("verdict", "unstable_roots", "hurwitz", "hurwitz_margin", "margin", "peak_omega",
            "sup_gain", "linf_gain")
    out = {k: np.empty(c["k_x"].size, dtype=object) for k in keys}
    for gid in np.unique(c["group"]):
        i = np.flatnonzero(c["group"] == gid)
        b = ss.certify_batch(c["k_x"][i], c["k_v"][i], c["k_a"][i], tau=c["tau"][i[0]],
                             delta=c["delta"][i[0]], headway=c["headway"][i[0]],
                             reaction_delay=c["theta"][i[0]])
        for k in keys:
            out[k][i] = getattr(b, k)
    return {k: (v.astype(str) if k == "verdict" else v.astype(bool) if k == "hurwitz"
                else v.astype(float)) for k, v in out.items()}


def run(n: int, seed: int = 0, progress: bool = False) -> dict[str, Any]:
    """Build the cases, run the certificate and the three checks, compare; the summary."""
    t0 = time.perf_counter()
    c = cases(n, seed)
    m = c["k_x"].size
    cert = certify_cases(c)
    t_cert = time.perf_counter() - t0
    args = (c["k_x"], c["k_v"], c["tau"], c["headway"], c["theta"])
    re, diff, cnt_spec, near_spec = spectral_rightmost(*args)
    cnt_pade, near_pade = pade_count(*args)
    sup, _w_sup, marg = sweep(c["k_x"], c["k_v"], c["k_a"], c["tau"], c["delta"], c["headway"],
                             c["theta"])
    resolved = diff <= RESOLVED
    stable = resolved & (re < -STAB_TOL)
    unstable = resolved & (re > STAB_TOL)
    gain_bad = sup > 1 + 1e-9
    gain_ok = (marg > GAIN_TOL) & (sup <= 1 + 1e-12)  # the grid and the refined maxima agree
    v = cert["verdict"]
    # a stated violation must hold where it was stated: |Γ(jω)| > 1 at the reported peak, in
    # double precision, or in 40-digit arithmetic where the excess is below 1e-9 (Ψ3 just below
    # 0 puts excesses of 1e-18 at ω ~ 1e-5, beyond the sweep and beyond doubles)
    stated = (v == "not_certified") & cert["hurwitz"]
    at_peak = np.abs(gamma(cert["peak_omega"], c["k_x"], c["k_v"], c["k_a"], c["tau"], c["delta"],
                           c["headway"], c["theta"]))
    holds = stated & (at_peak > 1 + 1e-9)
    fine = np.flatnonzero(stated & ~holds)
    holds[fine] = [excess_40_digits(c, i, float(cert["peak_omega"][i])) > 0 for i in fine]
    claimed_unstable = np.nan_to_num(cert["unstable_roots"], nan=-1) >= 1
    suspect = (v == "not_certified") & stable & gain_ok  # the sweep sees no violation ...
    masks = {
        "certified but unstable (spectral)": (v == "certified") & unstable,
        "certified but sup|Γ| > 1 + 1e-9 (sweep)": (v == "certified") & gain_bad,
        # ... and the certificate's witness does not hold in 40 digits either
        "not_certified but stable and |Γ| ≤ 1": suspect & ~holds,
        "root count ≥ 1 stated but stable (spectral)": claimed_unstable & stable,
        "violation stated (stable) but |Γ(jω_peak)| ≤ 1": stated & ~holds,
    }
    unsound = {k: int(np.sum(m)) for k, m in masks.items()}
    counted = np.isfinite(cert["unstable_roots"])
    clear = resolved & ~near_spec & ~near_pade  # no root within STAB_TOL of the axis
    n_cert = np.where(counted, np.nan_to_num(cert["unstable_roots"]), -1).astype(int)
    count_vs_spec = counted & clear & (n_cert != cnt_spec)
    count_vs_pade = counted & clear & (n_cert != cnt_pade)
    inc = v == "inconclusive"
    hm = cert["hurwitz_margin"]
    hm_ok = np.isfinite(hm)
    summary: dict[str, Any] = {
        "n": int(m), "seed": seed, "by_kind": {k: int(np.sum(c["kind"] == k)) for k in np.unique(c["kind"])},
        "verdicts": {k: int(np.sum(v == k)) for k in ("certified", "not_certified", "inconclusive")},
        "unsound": unsound, "unsound_total": int(sum(unsound.values())),
        "sweep_blind_witness_confirmed_40_digits": int(np.sum(suspect & holds)),
        "witnesses_checked_40_digits": int(fine.size),
        "spectral_unresolved": int(np.sum(~resolved)),
        "root_count_vs_spectral_mismatch": int(np.sum(count_vs_spec)),
        "root_count_vs_pade12_mismatch": int(np.sum(count_vs_pade)),
        "pade12_vs_spectral_mismatch": int(np.sum(clear & (cnt_pade != cnt_spec))),
        "inconclusive_share": float(np.mean(inc)),
        "inconclusive_by_kind": {k: int(np.sum(inc & (c["kind"] == k))) for k in np.unique(c["kind"])},
        "inconclusive_max_abs_rightmost_re": float(np.max(np.abs(re[inc]), initial=0.0)),
        "inconclusive_max_abs_margin_normalised": float(np.max(np.abs(marg[inc]), initial=0.0)),
        "inconclusive_far_from_boundary": int(np.sum(inc & (np.abs(re) > 1e-3) & (np.abs(marg) > 1e-3)
                                                     & (np.abs(sup - 1) > 1e-3))),
        "hurwitz_margin_shown": float(np.mean(hm_ok)),
        "hurwitz_margin_sign_vs_hurwitz_disagree": int(np.sum(hm_ok & ((hm > 0) != cert["hurwitz"]))),
        "hurwitz_margin_vs_spectral_max_abs_error":
            float(np.max(np.abs(-hm[hm_ok & resolved] - re[hm_ok & resolved]), initial=0.0)),
        "hurwitz_margin_vs_spectral_share_within_1e-6":
            float(np.mean(np.abs(-hm[hm_ok & resolved] - re[hm_ok & resolved]) < 1e-6)),
        "seconds_certificate": round(t_cert, 1), "seconds_total": round(time.perf_counter() - t0, 1),
        "load": os.getloadavg(),
    }
    summary["examples"] = {
        "unsound": _rows(c, cert, re, cnt_spec, cnt_pade, np.logical_or.reduce(list(masks.values()))),
        "sweep_blind_witness_confirmed": _rows(c, cert, re, cnt_spec, cnt_pade, suspect & holds, 3),
        "count_vs_spectral": _rows(c, cert, re, cnt_spec, cnt_pade, count_vs_spec),
        "inconclusive": _rows(c, cert, re, cnt_spec, cnt_pade, inc),
    }
    return summary


def excess_40_digits(c: dict[str, np.ndarray], i: int, w: float) -> float:
    """|Γ(jω)|² − 1 of case i at ω in 40-digit arithmetic (mpmath), straight from Γ."""
    import mpmath as mp

    with mp.workdps(40):
        kx, kv, ka, tau, d, T, th = (mp.mpf(float(c[k][i])) for k in
                                     ("k_x", "k_v", "k_a", "tau", "delta", "headway", "theta"))
        s = mp.mpc(0, w)
        er, ed = mp.exp(-th * s), mp.exp(-d * s)
        G = er * (kx + kv * s + ka * s * s * ed) / (tau * s**3 + s * s + er * ((kv + T * kx) * s + kx))
        return float(abs(G) ** 2 - 1)


def _rows(c, cert, re, cs, cp, mask, k: int = 5) -> list[dict[str, Any]]:
    out = []
    for i in np.flatnonzero(mask)[:k]:
        out.append({"K": [float(c["k_x"][i]), float(c["k_v"][i]), float(c["k_a"][i])],
                    "tau": float(c["tau"][i]), "delta": float(c["delta"][i]),
                    "headway": float(c["headway"][i]), "theta": float(c["theta"][i]),
                    "kind": str(c["kind"][i]), "verdict": str(cert["verdict"][i]),
                    "unstable_roots": float(cert["unstable_roots"][i]),
                    "spectral_rightmost_re": float(re[i]), "spectral_count": int(cs[i]),
                    "pade12_count": int(cp[i]), "peak_omega": float(cert["peak_omega"][i]),
                    "margin": float(cert["margin"][i])})
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=2000, help="number of cases (default 2000)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", help="also write the summary as JSON here")
    args = ap.parse_args(argv)
    s = run(args.n, args.seed)
    text = json.dumps(s, indent=1, ensure_ascii=False)
    print(text)
    if args.out:
        with open(args.out, "w", encoding="utf-8") as f:
            f.write(text + "\n")
    return 0 if s["unsound_total"] == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
