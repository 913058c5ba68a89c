"""The head-to-tail certificate against an independent check on random strings (issue 27).

For ``--n`` random strings of 2-12 vehicles (seeded), the head-to-tail verdict of
:func:`stringstab.certify.head_to_tail.decide` (the certificate :func:`stringstab.certify.api.certify_string`
gives the whole string) is set against a check that shares no code with it:

* **continuous time**: ∏_i |Γ_i(jω)| from the model's transfer function written out here in
  complex arithmetic, Γ = e^{−θ_r s}(k_x + k_v s + k_a s² e^{−δs})/(τs³ + s² +
  e^{−θ_r s}((k_v + T*k_x)s + k_x)) (a third of the vehicles get a reaction delay θ_r ∈ (0,
  0.5] s), on a fine grid (a log grid from 10⁻⁵ to 10³ rad/s and a linear one on [0, 20]
  rad/s), and internal stability from ``numpy.roots`` of each cubic (θ_r = 0) or of the cubic
  with e^{−θ_r s} replaced by its (10, 10) Padé approximant (θ_r > 0: an approximation, so a
  disagreement there is flagged for a look, within 10⁻⁶ of the axis it is not counted);
* **sampled data** (``--sampled-share`` of the strings, H = 0.1 s): the state-space ZOH
  discretisation with ``scipy.linalg.expm`` of ``tests/_sampled_truth.py`` (the predecessor's
  lag of each vehicle is the one ahead of it), on its θ grid, and the roots of each closed loop.

A verdict is **unsound** when it is ``certified`` but the check finds a vehicle with a root in
Re s ≥ 0 (|z| ≥ 1) or a product above 1 + 10⁻⁹ on the grid, or ``not_certified`` with every
vehicle stable while the check finds the product below 1 − 10⁻⁹ at the certificate's witness
frequency and at most 1 + 10⁻⁹ on the whole grid.  A tenth of the strings are placed near
the boundary (the last vehicle's T* bisected on a coarser grid of the check until the product's
peak is 1 ± 10^u, u uniform in [−9, −3]).  Conservatism: the inconclusive share, and how many of them the check
finds stable with a peak ≤ 1.

Prints a table and the machine load; asserts nothing (the test
``tests/certify/test_platoon_certify.py`` runs a small seeded version and asserts 0 unsound).

Example::

    python analysis/platoon_validate.py --n 10000          # ~15-30 min on 2 cores
    python analysis/platoon_validate.py --n 300 --seed 1
"""

from __future__ import annotations

import argparse
import importlib.util
import math
import os
import sys
import time
from collections import Counter
from pathlib import Path
from typing import Any

import numpy as np

from stringstab.certify.head_to_tail import StringArrays, Vehicle
from stringstab.certify.head_to_tail_sampled import SampledString
from stringstab.certify.string_certificate import default_grid
from stringstab.certify.string_decision import decide
from stringstab.params import Params

#: The sample time of the sampled strings, s.
H = 0.1
#: The continuous check's frequency grid, rad/s.
OMEGA = np.unique(np.concatenate([[0.0], np.geomspace(1e-5, 1e3, 30_000),
                                  np.linspace(0.0, 20.0, 40_001)]))
TOL = 1e-9


def _truth_module() -> Any:
    path = Path(__file__).resolve().parents[1] / "tests" / "_sampled_truth.py"
    spec = importlib.util.spec_from_file_location("_sampled_truth", path)
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


# ---------------------------------------------------------------------------
# Random strings
# ---------------------------------------------------------------------------
def random_vehicle(rng: np.random.Generator, reaction: float = 0.0) -> Vehicle:
    """A follower: recorded-car-like (ACC or human, k_a = 0), CAV-like, or anything (10 %).

    With probability ``reaction`` it gets a reaction delay θ_r uniform on (0, 0.5] s.
    """
    u = rng.random()
    if u < 0.5:
        kx, kv, ka = rng.uniform(0.02, 0.6), rng.uniform(0.05, 1.2), 0.0
        tau, delta, T = rng.uniform(0.1, 1.8), 0.0, rng.uniform(0.3, 2.5)
    elif u < 0.9:
        kx, kv, ka = rng.uniform(0.1, 2.0), rng.uniform(0.2, 2.0), rng.uniform(-0.5, 1.0)
        tau, delta, T = rng.uniform(0.05, 0.6), rng.uniform(0.0, 0.4), rng.uniform(0.3, 2.5)
    else:
        kx, kv, ka = rng.uniform(-0.2, 2.0), rng.uniform(-1.0, 2.0), rng.uniform(-1.0, 1.0)
        tau, delta, T = rng.uniform(0.02, 1.0), rng.uniform(0.0, 0.6), rng.uniform(0.0, 3.0)
    theta = float(rng.uniform(0.0, 0.5)) if rng.random() < reaction else 0.0
    return Vehicle(float(kx), float(kv), float(ka), Params(tau, delta, T, theta))


def gamma_jw(omega: np.ndarray, v: Vehicle) -> np.ndarray:
    """Γ(jω) of one vehicle, from the model written out (not from the toolkit's code)."""
    s = 1j * omega
    p = v.params
    e = np.exp(-p.reaction_delay * s)
    num = e * (v.k_x + v.k_v * s + v.k_a * s * s * np.exp(-p.delta * s))
    den = p.tau * s ** 3 + s * s + e * ((v.k_v + p.headway * v.k_x) * s + v.k_x)
    return num / den


def _pade(theta: float, m: int = 10) -> tuple[np.ndarray, np.ndarray]:
    """(num, den) of the (m, m) Padé approximant of e^{−θs}, highest power first."""
    c = np.array([math.factorial(2 * m - k) * math.factorial(m)
                  / (math.factorial(2 * m) * math.factorial(k) * math.factorial(m - k))
                  for k in range(m + 1)])
    den = c * theta ** np.arange(m + 1)
    num = den * (-1.0) ** np.arange(m + 1)
    return num[::-1], den[::-1]


def stable(v: Vehicle) -> bool | None:
    """Internally stable by ``numpy.roots`` (θ_r = 0), or by the Padé approximant (θ_r > 0).

    None where a Padé root lies within 10⁻⁶ of the axis (undecided by the approximation).
    """
    p = v.params
    P = np.array([p.tau, 1.0, 0.0, 0.0])
    Q = np.array([v.k_v + p.headway * v.k_x, v.k_x])
    if p.reaction_delay == 0:
        return bool(np.all(np.roots(np.polyadd(P, Q)).real < 0))
    num, den = _pade(p.reaction_delay)
    roots = np.roots(np.polyadd(np.polymul(P, den), np.polymul(Q, num)))
    if np.any(np.abs(roots.real) < 1e-6):
        return None
    return bool(np.all(roots.real < 0))


def product_continuous(s: list[Vehicle], omega: np.ndarray = OMEGA) -> np.ndarray:
    """∏ |Γ_i(jω)| on the grid."""
    out = np.ones(omega.shape)
    for v in s:
        out = out * np.abs(gamma_jw(omega, v))
    return out


def product_sampled(truth: Any, s: list[Vehicle], theta: np.ndarray, leader_tau: float) -> np.ndarray:
    """∏ |H_i(e^{jθ})| by the independent ZOH construction (predecessor lags in order)."""
    out = np.ones(theta.shape)
    tp = leader_tau
    for v in s:
        p = v.params
        out = out * np.abs(truth.pair_response(theta, v.k_x, v.k_v, v.k_a, p.tau, p.delta,
                                               p.headway, H, tau_prev=tp))
        tp = p.tau
    return out


def stable_sampled(truth: Any, v: Vehicle) -> bool:
    """Every root of the sampled closed loop inside the unit circle."""
    p = v.params
    return bool(np.all(np.abs(truth.pair_roots(v.k_x, v.k_v, p.tau, p.headway, H)) < 1))


def near_boundary(rng: np.random.Generator, s: list[Vehicle]) -> list[Vehicle]:
    """The last vehicle's T* bisected until the check's peak of the product is 1 ± 10^u, u ∈ [−9, −3]."""
    last = s[-1]
    grid = np.unique(np.concatenate([np.geomspace(1e-4, 50, 3000)]))
    rest = product_continuous(s[:-1], grid)

    def peak(T: float) -> float:
        v = Vehicle(last.k_x, last.k_v, last.k_a,
                    Params(last.params.tau, last.params.delta, T, last.params.reaction_delay))
        return float(np.max(rest * np.abs(gamma_jw(grid, v)))) if stable(v) else math.inf

    lo, hi = 0.0, 5.0
    if not peak(hi) <= 1.0 or peak(lo) <= 1.0:
        return s
    target = 1.0 + rng.choice([-1.0, 1.0]) * 10.0 ** rng.uniform(-9.0, -3.0)
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if peak(mid) > target else (lo, mid)
    T = hi
    p = last.params
    return [*s[:-1], Vehicle(last.k_x, last.k_v, last.k_a,
                             Params(p.tau, p.delta, T, p.reaction_delay))]


def strings(n: int, seed: int, near: float = 0.1,
            reaction: float = 1 / 3) -> list[list[Vehicle]]:
    """``n`` seeded random strings of 2-12 vehicles, a share ``near`` placed near the boundary."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        s = [random_vehicle(rng, reaction) for _ in range(int(rng.integers(2, 13)))]
        if rng.random() < near:
            s = near_boundary(rng, s)
        out.append(s)
    return out


# ---------------------------------------------------------------------------
# The comparison
# ---------------------------------------------------------------------------
def judge(verdict: str, witness: float, stable_all: bool, unstable_any: bool, peak: float,
          at_witness: float, undecided: bool = False) -> str:
    """``unsound``, ``sound``, ``conservative`` (an inconclusive verdict the check would certify)
    or ``unchecked`` (the Padé check of a delayed vehicle's stability undecided)."""
    if undecided:
        return "unchecked"
    if verdict == "certified":
        return "unsound" if (not stable_all or peak > 1 + TOL) else "sound"
    if verdict == "not_certified":
        if unstable_any:
            return "sound"
        if stable_all and at_witness < 1 - TOL and peak <= 1 + TOL:
            return "unsound"
        return "sound"
    return "conservative" if (stable_all and peak <= 1 + TOL) else "sound"


def run(n: int, seed: int, sampled_share: float = 0.1, near: float = 0.1,
        chunk: int = 200, reaction: float = 1 / 3) -> dict[str, Any]:
    """Certify and check ``n`` strings; return the counts (see the module docstring).

    Parameters
    ----------
    n, seed : int
        How many strings, and the seed.
    sampled_share : float
        Share of the strings certified as sampled-data loops (H = 0.1 s).
    near : float
        Share placed near the boundary.
    reaction : float
        Share of the vehicles of continuous strings with a reaction delay θ_r > 0.
    chunk : int
        Strings per batch of the certificate.

    Returns
    -------
    dict
        ``counts`` (Counter of (loop, verdict, judgement)), ``unsound`` (a list of the
        unsound strings), ``seconds`` (certificate time) and ``n``.
    """
    truth = _truth_module()
    rng = np.random.default_rng(seed + 1)
    kinds = ["sampled" if rng.random() < sampled_share else "continuous" for _ in range(n)]
    all_strings = strings(n, seed, near, reaction)
    # the sampled loop has no reaction delay (yet): those strings drop it
    all_strings = [s if k == "continuous" else
                   [Vehicle(v.k_x, v.k_v, v.k_a, Params(v.params.tau, v.params.delta,
                                                        v.params.headway)) for v in s]
                   for s, k in zip(all_strings, kinds)]
    counts: Counter[tuple[str, str, str]] = Counter()
    unsound: list[dict[str, Any]] = []
    seconds = 0.0
    groups: dict[tuple[str, int], list[int]] = {}
    for i, (s, k) in enumerate(zip(all_strings, kinds)):
        groups.setdefault((k, len(s)), []).append(i)
    for (kind, length), members in sorted(groups.items()):
        for c0 in range(0, len(members), chunk):
            ids = members[c0:c0 + chunk]
            batch = [all_strings[i] for i in ids]
            arrays = StringArrays.of(batch)
            t0 = time.perf_counter()
            if kind == "continuous":
                from stringstab.certify.head_to_tail import ContinuousString

                loop: Any = ContinuousString(arrays)
            else:
                loop = SampledString(arrays, H, np.array([b[0].params.tau for b in batch]))
            dec = decide(loop, n_grid=default_grid(length))
            seconds += time.perf_counter() - t0
            for j, (i, s) in enumerate(zip(ids, batch)):
                verdict = ("certified", "not_certified", "inconclusive")[int(dec.verdict[j])]
                undecided = False
                if kind == "continuous":
                    st = [stable(v) for v in s]
                    undecided = any(x is None for x in st)
                    stab = [bool(x) for x in st]
                    peak = float(product_continuous(s).max()) if all(stab) else math.inf
                    w = float(dec.argmin[j])
                    at_w = float(product_continuous(s, np.array([w]))[0])
                else:
                    stab = [stable_sampled(truth, v) for v in s]
                    peak = (float(product_sampled(truth, s, truth.THETA, s[0].params.tau).max())
                            if all(stab) else math.inf)
                    w = float(dec.argmin[j])
                    at_w = float(product_sampled(truth, s, np.array([max(w, 1e-9)]), s[0].params.tau)[0])
                j_ = judge(verdict, w, all(stab), not all(stab), peak, at_w, undecided)
                counts[(kind, verdict, j_)] += 1
                if j_ == "unsound":
                    unsound.append({"string": i, "kind": kind, "verdict": verdict, "peak": peak,
                                    "at_witness": at_w, "vehicles": [repr(v) for v in s]})
    return {"counts": counts, "unsound": unsound, "seconds": seconds, "n": n}


def main(argv: list[str] | None = None) -> int:
    """Run the comparison and print its table (module docstring)."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=10_000, help="random strings (default 10000)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--sampled-share", type=float, default=0.1)
    ap.add_argument("--near", type=float, default=0.1, help="share placed near the boundary")
    ap.add_argument("--reaction", type=float, default=1 / 3,
                    help="share of continuous vehicles with a reaction delay (default 1/3)")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    res = run(args.n, args.seed, args.sampled_share, args.near, reaction=args.reaction)
    counts = res["counts"]
    print(f"# {res['n']} strings of 2-12 vehicles, seed {args.seed}; load "
          + " ".join(f"{x:.2f}" for x in os.getloadavg()))
    print(f"{'loop':<11} {'verdict':<14} {'judgement':<13} {'strings':>8}")
    for key in sorted(counts):
        print(f"{key[0]:<11} {key[1]:<14} {key[2]:<13} {counts[key]:>8}")
    n_unsound = sum(v for k, v in counts.items() if k[2] == "unsound")
    n_incl = sum(v for k, v in counts.items() if k[1] == "inconclusive")
    n_cons = sum(v for k, v in counts.items() if k[2] == "conservative")
    print(f"unsound verdicts: {n_unsound} of {res['n']}")
    print(f"inconclusive: {n_incl} ({100 * n_incl / res['n']:.2f} %), of which the check finds "
          f"{n_cons} stable with a peak <= 1 (conservatism)")
    print(f"certificate time {res['seconds']:.1f} s ({1e3 * res['seconds'] / res['n']:.1f} ms per "
          f"string); total {time.perf_counter() - t0:.1f} s")
    for u in res["unsound"]:
        print("UNSOUND", u)
    return 0


if __name__ == "__main__":
    sys.exit(main())
