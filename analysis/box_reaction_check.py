"""An independent check of the robust certificate over a box with the reaction delay θ_r (issue 25, item 4).

Nothing here is used inside the certificate.  For random boxes τ × δ × T* × θ_r (widths from
points to wide; a tenth near the boundary: the centre's k_a bisected onto the edge of the point
certificate, then a narrow box around it) and gains, ``stringstab.certify_batch`` decides each
box.  For every box it checks *members* — the corners, random interior points and the member
that a local search finds closest to violating — with two truths written out here:

* **|Γ(jω)|** of Γ(s) = e^{−θ_r s}(k_x + k_v s + k_a s² e^{−δs}) / (τs³ + s² + e^{−θ_r s}((k_v +
  T*k_x)s + k_x)), complex exponentials evaluated directly, on 2,400 frequencies (logarithmic
  from 10⁻⁴ and linear) up to ω_hi, the root of τω³ − |k_a|ω² − (|c| + |k_v|)ω − 2|k_x|
  (beyond it |N(jω)| < |D(jω)|), the largest local maximum refined on a fine local grid;
* **stability** by the roots (``numpy.roots``) of (τs³ + s²)Q₁₂(θ_r s) + P₁₂(θ_r s)(cs + k_x),
  P₁₂/Q₁₂ the Padé(12, 12) approximant of e^{−x}: a member with a root of real part > 10⁻⁶ is
  unstable.

Reported:

* **unsound**: a certified box with a member found unstable or with |Γ| > 1 + 10⁻⁹ (must be 0);
* **false witness**: a not-certified box whose witness member is stable with |Γ(jω_w)| ≤ 1
  at the witness frequency (must be 0);
* **conservatism**: boxes not certified whose checked members all pass.

    nice -n 5 python analysis/box_reaction_check.py --n 10000 --seed 0   # the docs' table
    python analysis/box_reaction_check.py --n 200                        # a quick look

``tests/test_box_reaction_check.py`` runs a seeded few boxes of the same code.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from typing import Any

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np

import stringstab as ss

#: A member's gain above 1 + this is a violation.
GAIN_TOL = 1e-9
#: A Padé root with real part above this is unstable.
STAB_TOL = 1e-6
#: Padé order.
PADE = 12
#: Random interior members per box.
N_RANDOM = 24


def pade_coefficients(m: int = PADE) -> np.ndarray:
    """Coefficients a_k of the Padé(m, m) approximant of e^{−x}: Σ a_k(−x)^k / Σ a_k x^k."""
    return np.array([math.factorial(2 * m - k) * math.factorial(m)
                     / (math.factorial(2 * m) * math.factorial(k) * math.factorial(m - k))
                     for k in range(m + 1)])


_A = pade_coefficients()


def unstable_pade(kx: float, kv: float, tau: float, headway: float, theta: float) -> bool:
    """A root of the Padé(12, 12) characteristic polynomial in Re s > 10⁻⁶."""
    c = kv + headway * kx
    if theta > 0:
        k = np.arange(PADE + 1)
        q = _A * theta ** k  # Q(θs) in powers of s (ascending)
        p = _A * (-theta) ** k
    else:
        q = p = np.array([1.0])
    pol = np.polynomial.polynomial
    poly = pol.polyadd(pol.polymul([0.0, 0.0, 1.0, tau], q), pol.polymul([kx, c], p))
    roots = np.roots(poly[::-1])
    return bool(np.any(roots.real > STAB_TOL))


def gamma_abs(w: np.ndarray, kx: float, kv: float, ka: float, tau: Any, delta: Any,
              headway: Any, theta: Any) -> np.ndarray:
    """|Γ(jω)| of the transfer function written out (module docstring); rows broadcast."""
    s = 1j * w
    eth = np.exp(-theta * s)
    num = eth * (kx + kv * s + ka * s * s * np.exp(-delta * s))
    den = tau * s ** 3 + s * s + eth * ((kx * headway + kv) * s + kx)
    return np.asarray(np.abs(num) / np.abs(den))


def omega_hi(kx: float, kv: float, ka: float, tau: float, headway: float) -> float:
    """Beyond this frequency |Γ(jω)| < 1 for the member (module docstring)."""
    c = abs(kv + headway * kx)
    r = np.roots([tau, -abs(ka), -(c + abs(kv)), -2 * abs(kx)])
    return float(max(r.real.max(), 1e-3)) * 1.01


def peak_gain(kx: float, kv: float, ka: float, members: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """sup_ω |Γ(jω)| of each member (rows: τ, δ, T*, θ_r) and where: grid, then refined."""
    whi = max(omega_hi(kx, kv, ka, m[0], m[2]) for m in members)
    w = np.unique(np.concatenate([np.logspace(-4, math.log10(whi), 1200),
                                  np.linspace(1e-4, whi, 1200)]))
    t, d, h, q = (members[:, i:i + 1] for i in range(4))
    G = gamma_abs(w[None, :], kx, kv, ka, t, d, h, q)
    j = np.argmax(G, axis=1)
    best, bw = G[np.arange(len(members)), j], w[j]
    for i in range(len(members)):  # refine around the grid's maximum
        lo, hi = w[max(j[i] - 1, 0)], w[min(j[i] + 1, w.size - 1)]
        wl = np.linspace(lo, hi, 201)
        g = gamma_abs(wl, kx, kv, ka, *members[i])
        k = int(np.argmax(g))
        if g[k] > best[i]:
            best[i], bw[i] = g[k], wl[k]
    return best, bw


def closest_member(kx: float, kv: float, ka: float, lo: np.ndarray, hi: np.ndarray,
                   start: np.ndarray, rng: np.random.Generator, iters: int = 30) -> np.ndarray:
    """A local search for the member with the largest peak gain (random steps, shrinking)."""
    x = start.copy()
    fx = peak_gain(kx, kv, ka, x[None, :])[0][0]
    step = 0.25 * (hi - lo)
    for _ in range(iters):
        cand = np.clip(x + step * rng.uniform(-1, 1, (6, 4)), lo, hi)
        f = peak_gain(kx, kv, ka, cand)[0]
        k = int(np.argmax(f))
        if f[k] > fx:
            x, fx = cand[k], f[k]
        else:
            step = step * 0.6
    return x


def random_box(rng: np.random.Generator, near: bool) -> tuple[tuple[float, float, float], np.ndarray, np.ndarray]:
    """Gains and a box (lo, hi over τ, δ, T*, θ_r)."""
    tau = rng.uniform(0.05, 0.6)
    delta = rng.uniform(0.0, 0.5)
    theta = rng.uniform(0.0, 0.4)
    headway = 2.0 * (tau + theta) + rng.uniform(0.3, 3.0)
    centre = np.array([tau, delta, headway, theta])
    kx, kv, ka = rng.uniform(0.05, 1.2), rng.uniform(0.0, 2.0), rng.uniform(-0.6, 1.0)
    if near:  # bisect k_a onto the edge of the point certificate at the centre
        def ok(a: float) -> bool:
            return ss.check([kx], [kv], [a], tau=tau, delta=delta, headway=headway,
                            reaction_delay=theta).verdict[0] == "certified"
        a0, a1 = -0.6, 1.0
        if ok(a0) != ok(a1):
            for _ in range(30):
                m = 0.5 * (a0 + a1)
                if ok(m) == ok(a0):
                    a0 = m
                else:
                    a1 = m
            ka = a0 if ok(a0) else a1
        rel = 10.0 ** rng.uniform(-6, -2, 4)
    else:
        rel = np.where(rng.uniform(size=4) < 0.3, 0.0, 10.0 ** rng.uniform(-4, math.log10(0.6), 4))
    half = rel * np.maximum(centre, 0.05)
    lo = np.maximum(centre - half, [0.01, 0.0, 0.0, 0.0])
    hi = centre + half
    return (kx, kv, ka), lo, hi


def run(n: int, seed: int, *, verbose: bool = True) -> dict[str, Any]:
    """Check ``n`` seeded boxes; return the counts (module docstring)."""
    rng = np.random.default_rng(seed)
    counts = {"boxes": 0, "certified": 0, "not_certified": 0, "inconclusive": 0, "near": 0,
              "members_checked": 0, "unsound": 0, "false_witness": 0, "conservative": 0}
    bad: list[dict[str, Any]] = []
    t0 = time.time()
    for i in range(n):
        near = i % 10 == 9
        (kx, kv, ka), lo, hi = random_box(rng, near)
        iv = {k: (float(lo[j]), float(hi[j])) for j, k in
              enumerate(("tau", "delta", "headway", "reaction_delay"))}
        r = ss.certify_batch([kx], [kv], [ka], **iv)[0]
        counts["boxes"] += 1
        counts["near"] += near
        counts[r.verdict] += 1
        corners = np.array(np.meshgrid(*[[lo[j], hi[j]] for j in range(4)])).reshape(4, -1).T
        members = np.concatenate([corners, lo + (hi - lo) * rng.uniform(size=(N_RANDOM, 4))])
        peaks, _ = peak_gain(kx, kv, ka, members)
        start = members[int(np.argmax(peaks))]
        cm = closest_member(kx, kv, ka, lo, hi, start, rng, iters=12 if r.verdict == "certified" else 6)
        members = np.concatenate([members, cm[None, :]])
        peaks = np.concatenate([peaks, peak_gain(kx, kv, ka, cm[None, :])[0]])
        unstable = np.array([unstable_pade(kx, kv, m[0], m[2], m[3]) for m in members])
        counts["members_checked"] += len(members)
        fails = unstable | (peaks > 1.0 + GAIN_TOL)
        case = {"k": [kx, kv, ka], "lo": lo.tolist(), "hi": hi.tolist(), "verdict": r.verdict}
        if r.verdict == "certified" and fails.any():
            counts["unsound"] += 1
            bad.append({**case, "kind": "unsound", "member": members[int(np.argmax(fails))].tolist()})
        if r.verdict != "certified" and not fails.any():
            counts["conservative"] += 1
        if r.verdict == "not_certified":
            if hasattr(r, "witness_tau"):  # a box
                wm = (r.witness_tau, r.witness_delta, r.witness_headway, r.witness_reaction_delay)
                w_w = r.witness_omega
            else:  # a box of zero width is the point certificate
                wm, w_w = tuple(lo), (r.peak_omega if r.hurwitz else math.nan)
            holds = unstable_pade(kx, kv, wm[0], wm[2], wm[3]) if not math.isfinite(w_w) \
                else bool(gamma_abs(np.array([w_w]), kx, kv, ka, *wm)[0] > 1.0
                          or np.any(gamma_abs(np.logspace(-5, -1, 41), kx, kv, ka, *wm) > 1.0))
            if not holds and not unstable_pade(kx, kv, wm[0], wm[2], wm[3]):
                counts["false_witness"] += 1
                bad.append({**case, "kind": "false_witness", "member": list(wm), "omega": w_w})
        if verbose and (i + 1) % 500 == 0:
            print(f"{i + 1}/{n} boxes, {time.time() - t0:.0f} s: {counts}", file=sys.stderr)
    return {"counts": counts, "bad": bad[:20], "seconds": time.time() - t0,
            "load": os.getloadavg()}


def main(argv: list[str] | None = None) -> int:
    """Run the check from the command line; print the counts as JSON."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=200)
    ap.add_argument("--seed", type=int, default=0)
    a = ap.parse_args(argv)
    out = run(a.n, a.seed)
    print(json.dumps(out, indent=1))
    return 1 if out["counts"]["unsound"] or out["counts"]["false_witness"] else 0


if __name__ == "__main__":
    sys.exit(main())
