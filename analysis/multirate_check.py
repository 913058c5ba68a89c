"""Independent check of the multi-rate certificate on random loops (issue 26, item 7).

Neither check uses the certificate's code (``stringstab.certify.lifting``,
``lifted_frequency``, ``multirate``); both simulate the N-periodic link step by step:

* the *per-step model* is built here from the continuous state equations with
  ``scipy.linalg.expm`` (Van Loan's block exponential for the held inputs), with the full
  delay line of the predecessor's (a, u) samples (m + 1 of them, not the certificate's
  reduced buffer), the hold as a state, the message phase φ (random, not 0), and the
  fractional delay from another ``expm`` over the fraction of the step;
* (a) **the lifted frequency response by impulse responses**: the link is simulated from
  zero state for a unit impulse of u_{i−1} at each of the N steps of a message period until
  the state has decayed below 10⁻¹³; the lifted Markov parameters G_j (N × N) give
  G(e^{jθ}) = Σ_j G_j e^{−jθj} on an FFT grid of ≥ 4096 points of [0, 2π), refined by direct
  evaluation (zooming) around the grid's largest σ_max and at the certificate's witness;
* (b) **a long simulation** of the link driven by the complex periodic input
  u_{i−1, jN+l} = v_l e^{jθ*j} (v the top right singular vector of G(e^{jθ*}), θ* the peak
  of (a) away from 0 and π) for 300 message periods after the transient: its ℓ2 gain over
  the last 100 periods.

Verdicts are *unsound* if ``certified`` while (a) or (b) exceeds 1 + 10⁻⁷ or the truth's
monodromy matrix has an eigenvalue of modulus ≥ 1, or ``not_certified`` while the truth is
stable and σ_max ≤ 1 at the witness (and on the grid).  The conservatism is the share of
loops the truth finds string stable (sup ≤ 1 + 10⁻⁹) that the certificate leaves
``not_certified`` (must be none) or ``inconclusive``.

    python analysis/multirate_check.py --groups 100 --per-group 100 --seed 0

(10,000 random cases; N ∈ {1, 2, 5, 10, 20}, H ∈ {0.01, 0.02, 0.05, 0.1} s, δ a whole or a
fractional number of steps.)  ``tests/certify/test_multirate_check.py`` runs a small seeded version.
"""

from __future__ import annotations

import argparse
import math
import os
import time
from dataclasses import dataclass

# one BLAS thread per process: the batched linear algebra is many small problems, and a
# multi-threaded OpenBLAS waiting for busy cores made it 10-25x slower on a shared machine
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np
from scipy.linalg import expm

import stringstab as ss

NS = (1, 2, 5, 10, 20)
HS = (0.01, 0.02, 0.05, 0.1)


@dataclass(frozen=True)
class Case:
    """One group: the loop's parameters (the gains vary inside the group)."""

    tau: float
    delta: float
    headway: float
    H: float
    N: int
    phase: int


def step_model(tau: float, headway: float, H: float, delta: float):
    """Φ, Γ of [Δp, Δv, a_i, a_{i−1}] with held [u_i, u_{i−1}], and the delayed-sample row.

    Returns (Phi, Gam, m, cq): a_{i−1}(kH − δ) = cq[0] a_{i−1,k−m−1} + cq[1] u_{i−1,k−m−1}.
    """
    A = np.zeros((4, 4))
    A[0, 1], A[0, 2] = 1.0, -headway
    A[1, 2], A[1, 3] = -1.0, 1.0
    A[2, 2] = A[3, 3] = -1.0 / tau
    B = np.zeros((4, 2))
    B[2, 0] = B[3, 1] = 1.0 / tau
    Mv = np.zeros((6, 6))
    Mv[:4, :4], Mv[:4, 4:] = A, B
    E = expm(Mv * H)
    q = delta / H
    m = math.floor(q + 1e-9)
    frac = q - m
    if frac < 1e-9:
        frac = 0.0
    s = (1.0 - frac) * H  # a(kH − δ) = a((k − m − 1)H + s)
    es = expm(np.array([[-1.0 / tau, 1.0 / tau], [0.0, 0.0]]) * s)
    return E[:4, :4], E[:4, 4:], m, (es[0, 0], es[0, 1])


def simulate(case: Case, K: np.ndarray, up: np.ndarray) -> np.ndarray:
    """The follower's commands u_i for predecessor commands ``up`` (n, cols, T), zero state.

    State per triple and column: s (4), the delay line of (a_{i−1}, u_{i−1}) for the last
    m + 1 steps, and the held message h.
    """
    Phi, Gam, m, (c0, c1) = step_model(case.tau, case.headway, case.H, case.delta)
    n, cols, T = up.shape
    dt = up.dtype
    # one row per triple and column: X = [s (4), u_i, u_{i−1}], so s⁺ = X @ [Φᵀ; Γᵀ]
    X = np.zeros((n * cols, 6), dtype=dt)
    M = np.concatenate([Phi.T, Gam.T], axis=0)
    # the delay line as a ring: slot k mod (m + 1) holds (a_{i−1}, u_{i−1}) of step k
    ring_a = np.zeros((m + 1, n * cols), dtype=dt)
    ring_u = np.zeros((m + 1, n * cols), dtype=dt)
    h = np.zeros(n * cols, dtype=dt)
    kx, kv, ka = (np.repeat(K[:, i], cols) for i in range(3))
    upT = np.ascontiguousarray(up.reshape(n * cols, T).T)
    y = np.empty((T, n * cols), dtype=dt)
    for k in range(T):
        old = k % (m + 1)  # the slot of step k − m − 1 (zero before the start)
        if k % case.N == case.phase:
            h = c0 * ring_a[old] + c1 * ring_u[old]
        u = kx * X[:, 0] + kv * X[:, 1] + ka * h
        y[k] = u
        ring_a[old] = X[:, 3]
        ring_u[old] = upT[k]
        X[:, 4] = u
        X[:, 5] = upT[k]
        X[:, :4] = X @ M
    return y.T.reshape(n, cols, T)


def monodromy_radius(case: Case, K: np.ndarray) -> np.ndarray:
    """Spectral radius of the follower's own loop over one step (its N-th power is the monodromy's).

    The link is a cascade (predecessor lag → delay line → hold → follower), so the
    monodromy's spectrum is {λ^N} ∪ {e^{−NH/τ}} ∪ {0}: λ the eigenvalues of the follower's
    closed loop, computed here from Φ, Γ by ``numpy.linalg.eigvals``.
    """
    Phi, Gam, _, _ = step_model(case.tau, case.headway, case.H, case.delta)
    Acl = Phi[None, :3, :3] + Gam[None, :3, 0:1] * np.stack(
        [K[:, 0], K[:, 1], np.zeros(len(K))], axis=1)[:, None, :]
    return np.abs(np.linalg.eigvals(Acl)).max(axis=1)


def lifted_truth(case: Case, K: np.ndarray, max_steps: int = 40_000):
    """(a): the lifted Markov parameters of each triple by impulse responses (stable ones only)."""
    N = case.N
    rad = monodromy_radius(case, K)
    worst = float(rad.max()) if rad.size else 0.0
    _, _, m, _ = step_model(case.tau, case.headway, case.H, case.delta)
    steps = m + 2 * N + math.ceil(math.log(1e-13) / math.log(max(worst, 1e-3)))
    steps = min(max_steps, N * math.ceil(steps / N))
    up = np.zeros((len(K), N, steps))
    for l_ in range(N):
        up[:, l_, l_] = 1.0
    y = simulate(case, K, up)  # (n, l, T): response at step t to an impulse at step l
    J = steps // N
    G = y.reshape(len(K), N, J, N).transpose(0, 2, 3, 1)  # (n, j, i, l)
    tail = np.abs(G[:, -2:]).max(axis=(1, 2, 3))
    return G, tail, rad


def response(G: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Σ_j G_j e^{−jθj} at the θ of each row (theta: (n, k)) → (n, k, N, N)."""
    n, J, N, _ = G.shape
    arg = theta[:, :, None] * np.arange(J)[None, None, :]
    Gr = G.reshape(n, J, N * N)  # real: two real products, no complex copy of G
    return (np.cos(arg) @ Gr - 1j * (np.sin(arg) @ Gr)).reshape(n, theta.shape[1], N, N)


def smax(Gz: np.ndarray) -> np.ndarray:
    return np.sqrt(np.maximum(np.linalg.eigvalsh(np.swapaxes(Gz.conj(), -1, -2) @ Gz)[..., -1], 0))


def grid_sup(G: np.ndarray, P: int = 4096):
    """σ_max on the FFT grid of [0, π] and its argmax, zoomed by direct evaluation."""
    J = G.shape[1]
    P = max(P, 1 << math.ceil(math.log2(2 * J)))
    F = np.fft.fft(G, n=P, axis=1)[:, : P // 2 + 1]  # θ_p = 2πp/P ∈ [0, π]
    S = smax(F)
    th = 2 * np.pi * np.arange(P // 2 + 1) / P
    j = np.argmax(S, axis=1)
    best, where = S[np.arange(len(S)), j], th[j]
    half = np.full(len(S), 2 * np.pi / P)
    for _ in range(5):
        X = np.clip(where[:, None] + half[:, None] * np.linspace(-1, 1, 9)[None], 0, np.pi)
        Sx = smax(response(G, X))
        k = np.argmax(Sx, axis=1)
        upd = Sx[np.arange(len(S)), k] > best
        best = np.where(upd, Sx[np.arange(len(S)), k], best)
        where = np.where(upd, X[np.arange(len(S)), k], where)
        half /= 4
    # the interior peak (away from θ = 0 and π) for the simulation
    inner = (th > 0.05) & (th < np.pi - 0.05)
    ji = np.argmax(np.where(inner[None], S, -1), axis=1)
    return best, where, S, th, th[ji]


def simulated_gain(case: Case, K: np.ndarray, G: np.ndarray, theta: np.ndarray, settle: int):
    """(b): the ℓ2 gain of the link for u_{i−1} = v e^{jθj} over the last 100 periods."""
    N = case.N
    Gz = response(G, theta[:, None])[:, 0]
    _, _, Vh = np.linalg.svd(Gz)
    v = Vh[:, 0, :].conj()  # top right singular vector
    J = settle // N + 300
    j = np.arange(J)
    up = (v[:, :, None] * np.exp(1j * theta[:, None, None] * j[None, None, :]))  # (n, l, J)
    up = up.transpose(0, 2, 1).reshape(len(K), 1, J * N)
    y = simulate(case, K, up)[:, 0]
    w = slice((J - 100) * N, J * N)
    return np.sqrt(np.sum(np.abs(y[:, w]) ** 2, axis=1) / np.sum(np.abs(up[:, 0, w]) ** 2, axis=1))


def random_case(rng: np.random.Generator, N: int) -> Case:
    H = float(rng.choice(HS))
    if rng.random() < 0.5:  # a whole number of steps
        m = int(rng.integers(0, round(0.3 / H) + 1))
        delta = round(m * H, 10)
    else:
        delta = float(np.round(rng.uniform(0.0, 0.3), 4))
    return Case(tau=float(np.round(rng.uniform(0.05, 0.4), 3)), delta=delta,
                headway=float(np.round(rng.uniform(0.6, 2.0), 2)), H=H, N=N,
                phase=int(rng.integers(0, N)))


def random_gains(rng: np.random.Generator, n: int) -> np.ndarray:
    return np.stack([rng.uniform(0.05, 2.0, n), rng.uniform(-0.5, 2.0, n),
                     rng.uniform(-0.5, 1.2, n)], axis=1)


def check_group(case: Case, K: np.ndarray) -> dict[str, np.ndarray]:
    """Certificate and truth for one group; per-triple arrays."""
    b = ss.certify_batch(K[:, 0], K[:, 1], K[:, 2], tau=case.tau, delta=case.delta,
                         headway=case.headway, sample_time=case.H,
                         message_period=case.N * case.H,
                         message_phase=case.phase if case.N > 1 else None)
    verdict = np.asarray(b.verdict)
    n = len(K)
    rad = monodromy_radius(case, K)
    stable = rad < 1.0 - 1e-9
    sup = np.full(n, np.nan)
    sim = np.full(n, np.nan)
    at_w = np.full(n, np.nan)
    resolved = np.zeros(n, dtype=bool)
    idx = np.flatnonzero(stable)
    if idx.size:
        G, tail, _ = lifted_truth(case, K[idx])
        best, _, _, _, th_in = grid_sup(G)
        resolved[idx] = tail < 1e-10
        sup[idx] = best
        wth = np.asarray(b.peak_theta)[idx]
        at_w[idx] = smax(response(G, wth[:, None]))[:, 0]
        settle = G.shape[1] * case.N
        sim[idx] = simulated_gain(case, K[idx], G, th_in, settle)
    return {"verdict": verdict, "stable": stable, "radius": rad, "sup": sup, "sim": sim,
            "at_witness": at_w, "resolved": resolved,
            "cert_sup": np.asarray(b.sup_gain, dtype=float)}


def run(groups: int, per_group: int, seed: int, verbose: bool = True) -> dict[str, object]:
    rng = np.random.default_rng(seed)
    rows: list[dict[str, np.ndarray]] = []
    cases: list[Case] = []
    t0 = time.perf_counter()
    for g in range(groups):
        case = random_case(rng, NS[g % len(NS)])
        K = random_gains(rng, per_group)
        r = check_group(case, K)
        r["N"] = np.full(per_group, case.N)
        r["frac"] = np.full(per_group, abs(case.delta / case.H - round(case.delta / case.H)) > 1e-9)
        rows.append(r)
        cases.append(case)
        if verbose and (g + 1) % 10 == 0:
            print(f"  {g + 1}/{groups} groups, {time.perf_counter() - t0:.0f} s", flush=True)
    cat = {k: np.concatenate([r[k] for r in rows]) for k in rows[0]}
    v, st, res = cat["verdict"], cat["stable"], cat["resolved"]
    tol = 1e-7
    cert = v == "certified"
    unsound_cert = cert & (~st | (res & ((cat["sup"] > 1 + tol) | (cat["sim"] > 1 + tol))))
    nc = v == "not_certified"
    unsound_nc = nc & st & res & (cat["sup"] <= 1 + 1e-12) & (cat["at_witness"] <= 1 + 1e-12)
    truth_ok = st & res & (cat["sup"] <= 1 + 1e-9)
    out = {
        "cases": int(v.size), "seed": seed, "stable": int(st.sum()), "resolved": int(res.sum()),
        "certified": int(cert.sum()), "not_certified": int(nc.sum()),
        "inconclusive": int((v == "inconclusive").sum()),
        "unsound_certified": int(unsound_cert.sum()), "unsound_not_certified": int(unsound_nc.sum()),
        "truth_string_stable": int(truth_ok.sum()),
        "truth_stable_but_inconclusive": int((truth_ok & (v == "inconclusive")).sum()),
        "truth_stable_but_not_certified": int((truth_ok & nc).sum()),
        "max_sup_certified": float(np.nanmax(np.where(cert & res, cat["sup"], np.nan)))
        if (cert & res).any() else float("nan"),
        "max_sim_certified": float(np.nanmax(np.where(cert & res, cat["sim"], np.nan)))
        if (cert & res).any() else float("nan"),
        "witness_gap": float(np.nanmax(np.abs(np.where(nc & st & res, cat["at_witness"] - cat["cert_sup"], np.nan))))
        if (nc & st & res).any() else float("nan"),
        "per_N": {int(N): {"cases": int((cat["N"] == N).sum()),
                           "certified": int((cert & (cat["N"] == N)).sum()),
                           "truth_string_stable": int((truth_ok & (cat["N"] == N)).sum()),
                           "inconclusive": int(((v == "inconclusive") & (cat["N"] == N)).sum())}
                  for N in NS},
        "fractional_delay_cases": int(cat["frac"].sum()),
        "seconds": time.perf_counter() - t0,
        "load": os.getloadavg(),
        "rows": cat,
    }
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--groups", type=int, default=100)
    ap.add_argument("--per-group", type=int, default=100)
    ap.add_argument("--seed", type=int, default=0)
    a = ap.parse_args()
    out = run(a.groups, a.per_group, a.seed)
    out.pop("rows")
    for k, v in out.items():
        print(f"{k}: {v}")


if __name__ == "__main__":
    main()
