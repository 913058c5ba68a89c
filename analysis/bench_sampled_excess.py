"""Cost of the sampled certificate's ``sup_gain_excess`` (issue 21, item 5).

Times :func:`stringstab.sampled.certify_sampled_batch` on 20,000 random triples in [−2, 2]³
(τ = 0.1, δ = 0.2, T* = 1.1, H = 0.1) with the violation-peak search of not-certified Schur
rows, and in the same run with that search replaced by a no-op (the code before it), and
prints the ratio and the machine load.  Run: ``.venv/bin/python analysis/bench_sampled_excess.py``.
"""

from __future__ import annotations

import os
import time
from unittest import mock

import numpy as np

from stringstab import sampled


def _no_search(co, m, kappa, cand):  # type: ignore[no-untyped-def]
    n = kappa.size
    return np.full(n, -np.inf), np.zeros(n)


def main(n: int = 20_000, repeats: int = 3) -> None:
    k = np.random.default_rng(21).uniform(-2.0, 2.0, (3, n))
    kw = dict(tau=0.1, delta=0.2, headway=1.1, sample_time=0.1)
    sampled.certify_sampled_batch(*k[:, :200], **kw)  # warm-up
    t_new, t_old = [], []
    for _ in range(repeats):
        with mock.patch.object(sampled, "_violation_peak", _no_search):
            t0 = time.perf_counter()
            old = sampled.certify_sampled_batch(*k, **kw)
            t_old.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        new = sampled.certify_sampled_batch(*k, **kw)
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


if __name__ == "__main__":
    main()
