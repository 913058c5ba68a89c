"""Independent check of the sampled certificate with a reaction delay θ_r (issue 25 item 3).

The truth here shares no code with the certificate (``stringstab.certify.lifting_reaction``,
``stein``, ``lifted_frequency``, ``multirate``): it is built from the continuous state
equations of one vehicle in absolute coordinates, x = [p, v, a] with τ a' = w − a, and the held
input as a fourth state (w' = 0), by ``scipy.linalg.expm`` of that 4 × 4 augmented matrix over
the pieces [0, fH) and [fH, H) of a step:

* x_{k+1} = Φ x_k + Γ0 c_{k−q−1} + Γ1 c_{k−q} (c the command, θ_r = (q + f)H by the toolkit's
  split rule), and the delayed sample a(kH − δ) from another expm over the fraction of the step;
* **stability**: the eigenvalues of the follower's closed loop (x and the delay line of its
  last q + 1 commands, written out here), by ``numpy.linalg.eigvals``;
* **|H(e^{jθ})|** by the input-output formula H = (k_x P_p + k_v P_v + k_a Q)/(1 + k_x(P_p + T*P_v)
  + k_v P_v), P_p, P_v, Q the vehicle's transfer functions from its command to its sampled
  position, speed and delayed acceleration (3 × 3 solves at each z), on a grid of 4,000 points of
  [0, π] plus a golden-section zoom around the grid's largest value and at the witness;
* **a long fine-step simulation** (a sample of cases): the two-vehicle loop integrated with a
  step H/50 (exact exponential of the lag, held inputs), driven by a sinusoidal predecessor
  command at the peak frequency; the ratio of the follower's and the predecessor's command
  amplitudes over the last periods, compared with |H| (tolerance 2 %).

Verdicts are *unsound* if ``certified`` while the truth is unstable or sup|H| > 1 + 10⁻⁷, or
``not_certified`` while the truth is stable and |H| ≤ 1 + 10⁻⁷ on the grid and at the witness.
Conservatism: the share of truth-string-stable loops left ``inconclusive`` or ``not_certified``.

    nice -n 5 .venv/bin/python analysis/sampled_reaction_check.py --n 2000 --seed 0

Random τ ∈ [0.05, 1], δ ∈ [0, 0.4] (a third a whole number of steps), T* ∈ [0.3, 2.5],
H ∈ {0.01, 0.05, 0.1, 0.2}, θ_r = (q + f)H with q ∈ {0, 1, 2, 5} and f = 0 or uniform (never
θ_r = 0), gains k_x ∈ [0, 2], k_v ∈ [0, 3], k_a ∈ [0, 1]; a tenth of the cases moved to within
10⁻³ (relative) of the truth's boundary in the time gap T* (bisection of the truth's verdict).  Cases are drawn in groups of 10
sharing (τ, δ, T*, H, θ_r).
"""

from __future__ import annotations

import argparse
import math
import os
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np
from scipy.linalg import expm

import stringstab as ss

HS = (0.01, 0.05, 0.1, 0.2)
QS = (0, 1, 2, 5)
GRID = 4000
TOL = 1e-7


def split(theta: float, H: float) -> tuple[int, float]:
    """θ = (q + f)H with the toolkit's documented rule (a whole number within 1e-9 H is one)."""
    n = round(theta / H)
    if abs(theta - n * H) <= 1e-9 * H:
        return int(n), 0.0
    r = math.fmod(theta, H)
    return round((theta - r) / H), r / H


def piece(t: float, tau: float) -> np.ndarray:
    """exp of the augmented [p, v, a, w] model over t (w held)."""
    M = np.zeros((4, 4))
    M[0, 1] = M[1, 2] = 1.0
    M[2, 2], M[2, 3] = -1.0 / tau, 1.0 / tau
    return expm(M * t)


class Vehicle:
    """One vehicle's discrete model with the reaction delay, built by expm."""

    def __init__(self, tau: float, delta: float, H: float, theta: float):
        self.q, f = split(theta, H)
        m, eps = split(delta, H)
        self.m = m
        fH = f * H
        E1 = piece(H - fH, tau)
        if fH > 0:
            E0 = piece(fH, tau)
            self.Phi = (E1 @ E0)[:3, :3]
            self.G0 = (E1[:3, :3] @ E0[:3, 3])  # c_{k-q-1}, first piece then free
            self.G1 = E1[:3, 3]
        else:
            self.Phi = E1[:3, :3]
            self.G0 = np.zeros(3)
            self.G1 = E1[:3, 3]
        s = (1.0 - eps) * H  # a(kH − δ) = a at s into step k − m − 1
        if s <= fH:
            Es = piece(s, tau)
            self.ca, self.d0, self.d1 = Es[2, :3], Es[2, 3], 0.0
        else:
            Er = piece(s - fH, tau)
            E0 = piece(fH, tau) if fH > 0 else np.eye(4)
            self.ca = (Er[2, :3] @ E0[:3, :3])
            self.d0 = float(Er[2, :3] @ E0[:3, 3]) if fH > 0 else 0.0
            self.d1 = Er[2, 3]

    def transfers(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """P_p(z), P_v(z), Q(z): command → sampled p, v and a(kH − δ)."""
        W = z[:, None, None] * np.eye(3) - self.Phi
        zi = 1.0 / z
        inp = self.G0[None, :] * zi[:, None] ** (self.q + 1) + self.G1[None, :] * zi[:, None] ** self.q
        X = np.linalg.solve(W, inp[..., None])[..., 0]
        Qa = (X @ self.ca + self.d0 * zi ** (self.q + 1) + self.d1 * zi ** self.q) * zi ** (self.m + 1)
        return X[:, 0], X[:, 1], Qa

    def closed_loop(self, kx: float, kv: float, T: float) -> np.ndarray:
        """The follower's closed-loop matrix: state [x, c_{k−1}, …, c_{k−q−1}]."""
        L = self.q + 1
        n = 3 + L
        A = np.zeros((n, n))
        K = np.array([-kx, -(kx * T + kv), 0.0])  # c_k = K x_k (own part of the law)
        A[:3, :3] = self.Phi
        A[:3, 3 + L - 1] += self.G0  # c_{k−q−1}
        if self.q == 0:
            A[:3, :3] += np.outer(self.G1, K)
        else:
            A[:3, 3 + self.q - 1] += self.G1
        A[3, :3] = K
        for j in range(1, L):
            A[3 + j, 3 + j - 1] = 1.0
        return A


def gain(v: Vehicle, k: np.ndarray, T: float, th: np.ndarray) -> np.ndarray:
    """|H(e^{jθ})| by the input-output formula."""
    z = np.exp(1j * np.asarray(th, dtype=float))
    Pp, Pv, Qa = v.transfers(z)
    num = k[0] * Pp + k[1] * Pv + k[2] * Qa
    den = 1.0 + k[0] * (Pp + T * Pv) + k[1] * Pv
    return np.abs(num / den)


def golden_max(fn, lo: float, hi: float, it: int = 60) -> tuple[float, float]:
    """A golden-section search for a local maximum of fn on [lo, hi]."""
    g = (math.sqrt(5) - 1) / 2
    a, b = lo, hi
    c, d = b - g * (b - a), a + g * (b - a)
    fc, fd = fn(c), fn(d)
    for _ in range(it):
        if fc > fd:
            b, d, fd = d, c, fc
            c = b - g * (b - a)
            fc = fn(c)
        else:
            a, c, fc = c, d, fd
            d = a + g * (b - a)
            fd = fn(d)
    return (fc, c) if fc > fd else (fd, d)


def truth(v: Vehicle, k: np.ndarray, T: float, witness: float) -> tuple[bool, float, float]:
    """(stable, sup|H| found, where)."""
    rho = np.abs(np.linalg.eigvals(v.closed_loop(k[0], k[1], T))).max()
    th = np.linspace(1e-9, np.pi, GRID)
    g = gain(v, k, T, th)
    j = int(np.argmax(g))
    best, where = float(g[j]), float(th[j])
    for c in {j, int(np.clip(np.searchsorted(th, witness), 0, GRID - 1))}:
        lo, hi = th[max(c - 1, 0)], th[min(c + 1, GRID - 1)]
        b, w = golden_max(lambda x: float(gain(v, k, T, np.array([x]))[0]), lo, hi)
        if b > best:
            best, where = b, w
    wg = float(gain(v, k, T, np.array([max(witness, 1e-9)]))[0])
    if wg > best:
        best, where = wg, witness
    return bool(rho < 1.0), best, where


def simulate(tau: float, delta: float, T: float, H: float, theta: float, k: np.ndarray,
             th: float, sub: int = 50, periods: int = 60) -> float:
    """The follower/predecessor command amplitude ratio of a fine-step simulation at θ."""
    dt = H / sub
    w = th / H
    n_steps = max(int(periods * 2 * math.pi / max(th, 1e-3)), 400)
    n_steps = min(n_steps, 20000)
    q, f = split(theta, H)
    m, eps = split(delta, H)
    E = math.exp(-dt / tau)
    xs = np.zeros((2, 3))  # [p, v, a] of predecessor (0) and follower (1)
    xs[0, 0] = 10.0  # gap; relative quantities only matter
    cmd = np.zeros((2, n_steps + 1))
    a_hist: list[float] = [0.0]  # predecessor a at every fine time (index = fine step)
    fine = 0
    for kstep in range(n_steps):
        cmd[0, kstep] = math.sin(w * kstep * H)
        # the delayed sample a_{i-1}(kH − δ): fine index kH − δ on the fine grid (exact at
        # multiples of dt: δ rounded to it, the check's resolution)
        idx = fine - round((m + eps) * sub)
        a_d = a_hist[idx] if idx >= 0 else 0.0
        gap = xs[0, 0] - xs[1, 0] - 10.0 - T * xs[1, 1]
        cmd[1, kstep] = k[0] * gap + k[1] * (xs[0, 1] - xs[1, 1]) + k[2] * a_d
        for j in range(sub):
            t_in = j * dt
            for i in range(2):
                src = kstep - q - 1 if t_in < f * H - 1e-12 else kstep - q
                wv = cmd[i, src] if src >= 0 else 0.0
                a0 = xs[i, 2]
                a1 = E * a0 + (1 - E) * wv
                # exact integrals of the lag over dt
                ia = tau * (1 - E) * a0 + (dt - tau * (1 - E)) * wv
                iia = tau * (dt - tau * (1 - E)) * a0 + (dt * dt / 2 - tau * (dt - tau * (1 - E))) * wv
                xs[i, 0] += xs[i, 1] * dt + iia
                xs[i, 1] += ia
                xs[i, 2] = a1
            a_hist.append(xs[0, 2])
            fine += 1
    last = slice(n_steps // 2, n_steps)
    return float(np.max(np.abs(cmd[1, last])) / np.max(np.abs(cmd[0, last])))


def boundary_headway(v: Vehicle, k: np.ndarray) -> float | None:
    """The time gap T* where the truth's verdict changes (bisection on [0.05, 8] s), if any."""
    def ok(T: float) -> bool:
        st, sup, _ = truth(v, k, T, 0.0)
        return st and sup <= 1.0 + 1e-12
    lo, hi = 0.05, 8.0
    if ok(lo) == ok(hi):
        return None
    for _ in range(30):
        mid = 0.5 * (lo + hi)
        if ok(mid) == ok(lo):
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def run(n: int, seed: int, simulate_every: int) -> tuple[dict[str, int], dict[int, list[int]]]:
    """The check of n cases (groups of 10): the counts, and per q [cases, unsound, conservative]."""
    rng = np.random.default_rng(seed)
    rows = {"cases": 0, "certified": 0, "not_certified": 0, "inconclusive": 0,
            "near_boundary": 0, "truth_ss": 0, "unsound": 0, "wrong_not_certified": 0,
            "conservative": 0, "simulated": 0, "sim_mismatch": 0}
    by_q: dict[int, list[int]] = {}
    groups = max(1, n // 10)
    for g in range(groups):
        tau = float(rng.uniform(0.05, 1.0))
        H = float(rng.choice(HS))
        delta = float(rng.integers(0, 5) * H) if rng.random() < 1 / 3 else float(rng.uniform(0, 0.4))
        T = float(rng.uniform(0.3, 2.5))
        q = int(rng.choice(QS))
        f = 0.0 if (rng.random() < 0.5 and q > 0) else float(rng.uniform(0.05, 0.95))
        theta = (q + f) * H
        K = np.column_stack([rng.uniform(0, 2, 10), rng.uniform(0, 3, 10), rng.uniform(0, 1, 10)])
        v = Vehicle(tau, delta, H, theta)
        near = np.zeros(10, dtype=bool)
        Ts = np.full(10, T)
        if g % 10 == 0:  # a tenth near the boundary: each case at its own boundary T*
            for i in range(10):
                tb = boundary_headway(v, K[i])
                if tb is not None:
                    Ts[i] = tb * (1.0 + float(rng.choice([-1, 1])) * 1e-3)
                    near[i] = True
        if near.any():
            parts = [ss.certify_batch(K[i:i + 1, 0], K[i:i + 1, 1], K[i:i + 1, 2], tau=tau,
                                      delta=delta, headway=float(Ts[i]), sample_time=H,
                                      reaction_delay=theta) for i in range(10)]
            verdicts = [str(p_.verdict[0]) for p_ in parts]
            peaks = [float(p_.peak_theta[0]) for p_ in parts]
            schur = [bool(p_.schur[0]) for p_ in parts]
        else:
            b = ss.certify_batch(K[:, 0], K[:, 1], K[:, 2], tau=tau, delta=delta, headway=T,
                                 sample_time=H, reaction_delay=theta)
            verdicts, peaks, schur = b.verdict.tolist(), b.peak_theta.tolist(), b.schur.tolist()
        for i in range(10):
            T = float(Ts[i])
            st, sup, where = truth(v, K[i], T, peaks[i])
            ss_true = st and sup <= 1.0 + 1e-9
            verdict = verdicts[i]
            rows["cases"] += 1
            rows[verdict] += 1
            rows["near_boundary"] += int(near[i])
            rows["truth_ss"] += int(ss_true)
            cell = by_q.setdefault(v.q, [0, 0, 0])
            cell[0] += 1
            if verdict == "certified" and (not st or sup > 1.0 + TOL):
                rows["unsound"] += 1
                cell[1] += 1
                print("UNSOUND", tau, delta, T, H, theta, K[i].tolist(), st, sup, where)
            if verdict == "not_certified" and st and sup <= 1.0 + TOL \
                    and schur[i]:
                rows["wrong_not_certified"] += 1
                print("WRONG not_certified", tau, delta, T, H, theta, K[i].tolist(), sup)
            if ss_true and verdict != "certified":
                rows["conservative"] += 1
                cell[2] += 1
            if simulate_every and rows["cases"] % simulate_every == 0 and st and where > 0.05:
                r = simulate(tau, delta, T, H, theta, K[i], where)
                rows["simulated"] += 1
                if abs(r - sup) > 0.02 * max(1.0, sup):
                    rows["sim_mismatch"] += 1
                    print("SIM", tau, delta, T, H, theta, K[i].tolist(), r, sup, where)
    return rows, by_q


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=2000, help="cases (groups of 10)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--simulate-every", type=int, default=100,
                    help="simulate one case in this many (0: none)")
    a = ap.parse_args()
    t0 = time.perf_counter()
    rows, by_q = run(a.n, a.seed, a.simulate_every)
    el = time.perf_counter() - t0
    print(f"\nsampled θ_r check: seed {a.seed}, {rows['cases']} cases, {el:.0f} s, "
          f"load {os.getloadavg()[0]:.2f}")
    print("| " + " | ".join(rows) + " |")
    print("|" + "---|" * len(rows))
    print("| " + " | ".join(str(v) for v in rows.values()) + " |")
    print("\n| q | cases | unsound | truth-stable not certified |\n|---|---|---|---|")
    for qq in sorted(by_q):
        c = by_q[qq]
        print(f"| {qq} | {c[0]} | {c[1]} | {c[2]} |")


if __name__ == "__main__":
    main()
