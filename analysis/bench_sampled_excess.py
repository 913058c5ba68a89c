"""Cost of the sampled certificate's ``sup_gain_excess`` (issue 21, item 5).

Times the sampled certificate (:func:`stringstab.certify.api.certify_batch` with a sample time) on 20,000 random triples in [−2, 2]³
(τ = 0.1, δ = 0.2, T* = 1.1, H = 0.1) with the violation-peak search of not-certified Schur
rows, and in the same run with that search replaced by a no-op (the code before it), and
prints the ratio and the machine load; then, on rows whose Ψ3 is just below 0, how many
report sup|H| = 1.0 at θ = 0 without the search and how many have an excess > 0 with it.  Run: ``.venv/bin/python analysis/bench_sampled_excess.py``.
"""

from __future__ import annotations

import os
import time
from unittest import mock

import numpy as np

from stringstab.certify import sampled
from stringstab.certify.api import certify_batch


def _no_search(co, m, kappa, cand):  # type: ignore[no-untyped-def]
    n = kappa.size
    return np.full(n, -np.inf), np.zeros(n)


def main(n: int = 20_000, repeats: int = 3) -> None:
    k = np.random.default_rng(21).uniform(-2.0, 2.0, (3, n))
    kw = dict(tau=0.1, delta=0.2, headway=1.1, sample_time=0.1)
    certify_batch(*k[:, :200], **kw)  # warm-up
    t_new, t_old = [], []
    for _ in range(repeats):
        with mock.patch.object(sampled, "violation_peak", _no_search):
            t0 = time.perf_counter()
            old = certify_batch(*k, **kw)
            t_old.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        new = certify_batch(*k, **kw)
        t_new.append(time.perf_counter() - t0)
    assert (old.verdict == new.verdict).all()
    viol = (new.verdict == "not_certified") & new.schur
    print(f"triples {n}: not certified and Schur {int(viol.sum())}, "
          f"certified {int(new.certified.sum())}")
    print(f"min time without the search {min(t_old):.3f} s, with it {min(t_new):.3f} s, "
          f"ratio {min(t_new) / min(t_old):.3f}; load average {os.getloadavg()}")
    print(f"rows whose sup_gain rounds to 1.0 but sup_gain_excess > 0: "
          f"{int((viol & (new.sup_gain == 1.0)).sum())}; "
          f"min excess over violating rows {new.sup_gain_excess[viol].min():.3g}")



def near_zero(n: int = 86, H: float = 0.1) -> None:
    """Rows whose Ψ3 is just below 0 (k_x a relative 1e-10 past the root, random k_v, k_a):
    how many report sup|H| = 1.0 at θ = 0, and how many have sup_gain_excess > 0 and θ > 0."""
    from scipy.optimize import brentq

    from stringstab.certify.margin import coefficients

    def psi3(kx: float, kv: float, ka: float) -> float:
        c = coefficients(kx, kv, ka, tau=0.1, delta=0.2, headway=1.1)
        return float(c.b + c.cx)

    rng = np.random.default_rng(86)
    rows: list[tuple[float, float, float]] = []
    while len(rows) < n:
        kv, ka = rng.uniform(-2.0, 2.0, 2)
        try:
            x0 = brentq(psi3, 1e-3, 2.0, args=(kv, ka), xtol=1e-15)
        except ValueError:
            continue
        rows += [(x, kv, ka) for x in (x0 * (1 + 1e-10), x0 * (1 - 1e-10)) if psi3(x, kv, ka) < 0]
    k = np.array(rows[:n]).T
    kw = dict(tau=0.1, delta=0.2, headway=1.1, sample_time=H)
    k = np.tile(k, 50)  # 4,300 rows, nearly all searched: the worst case of the extra cost
    with mock.patch.object(sampled, "violation_peak", _no_search):
        t0 = time.perf_counter()
        old = certify_batch(*k, **kw)
        t_old = time.perf_counter() - t0
    t0 = time.perf_counter()
    new = certify_batch(*k, **kw)
    t_new = time.perf_counter() - t0
    print(f"  (x50: {k.shape[1]} rows: {t_old:.3f} s without the search, {t_new:.3f} s with it, "
          f"ratio {t_new / t_old:.3f}; load average {os.getloadavg()})")
    v = ((new.verdict == "not_certified") & new.schur)[:n]
    o_sup, o_th = old.sup_gain[:n], old.peak_theta[:n]
    ex, th = new.sup_gain_excess[:n], new.peak_theta[:n]
    print(f"Ψ3 just below 0, H = {H}: {n} rows, {int(v.sum())} not certified and Schur; "
          f"without the search {int((v & (o_sup == 1.0) & (o_th == 0)).sum())} "
          f"report sup|H| = 1.0 at θ = 0; with it {int((v & (ex > 0)).sum())} "
          f"have sup_gain_excess > 0 and {int((v & (th > 0)).sum())} θ_peak > 0 "
          f"(excess from {ex[v].min():.2g} to {ex[v].max():.2g})")


if __name__ == "__main__":
    main()
    for h in (0.05, 0.1, 0.2):
        near_zero(H=h)
