"""Benchmark of the exact certificate against python-control and a dense frequency sweep.

The same ``--n`` random gain triples K uniform in [-2, 2]³ (``--seed``) are certified

(a) by :func:`stringstab.certify.api.certify_batch` (exact delay, sound), in one call;
(b) the python-control way, one triple at a time: the delay replaced by
    ``control.pade(delta, 5)``, our own stability check of the poles
    (``control.poles``), then ``control.norm(sys, "inf")`` (which alone returns
    the L∞ norm and never checks stability); verdict "certified" when stable and
    the norm is ≤ 1 + 1e-5 (``control.norm``'s own bisection tolerance is a
    relative 1e-6, so a triple whose true supremum is exactly |Γ(0)| = 1 comes
    back as 1 + O(1e-6)).  ``--pade-subset`` times (b) on a random subset when
    the full set is too slow;
(c) by an independent check: Hurwitz by ``numpy.roots`` and, for stable Γ, a
    ``--points`` (10⁶) point sweep of |Γ(jω)| with :func:`stringstab.certify.frequency.gain`
    on [0, Ω], where Ω is the largest root of the cubic
    ½τω³ − |k_a|ω² − (½|c| + |k_v|)ω − |k_x| (c = k_v + T*k_x), beyond which
    |Γ(jω)| ≤ (|k_x| + |k_v|ω + |k_a|ω²) / (ω(τω² − |c|)) ≤ ½.

A triple is *borderline* for the sweep when its largest pole real part is within
1e-9 of 0, or when m = min over swept ω ≥ 1e-3 of (1 − |Γ(jω)|²)/min(1, ω²)
satisfies |m| ≤ 1e-6 (m → Ψ3/k_x² as ω → 0, where |Γ| → 1; the plain
``|peak − 1|`` cannot separate anything since every Hurwitz triple has
|Γ(0)| = 1).  Otherwise the sweep decides: certified iff Hurwitz and m > 0.

(d) the other loops, in the same run, on the same triples, through the same entry points
    (:func:`stringstab.certify.api.certify_batch` and :func:`~stringstab.certify.api.check`
    with ``sample_time`` and intervals): the sampled-data certificate at Δt = 0.1 s (δ on a
    multiple of Δt) and at Δt = 0.08 s (δ/Δt = 2.5), the robust certificate over
    τ ∈ [0.1, 0.2], δ ∈ [0.15, 0.25], T* ∈ [1.0, 1.2] in continuous time and, on the first
    ``--n-robust-sampled`` triples (it is the slow one), sampled at Δt = 0.1 s with
    heterogeneous lags; each as ms per triple and as the ratio to (a), with the verdict counts.

(e) the reaction delay θ_r (issue 25), in the same run, on the same triples: ``certify_batch``
    and ``check`` with ``reaction_delay`` = 0.1, 0.2, 0.5 s (the quasi-polynomial certificate,
    :mod:`stringstab.certify.reaction`) as ratios to (a) and to the θ_r = 0 ``check`` (target:
    ≤ 10×), and ``reaction_delay=0.0`` (today's code path) as a ratio to (a) (target: 1×).
    ``--compare-with DIR`` also times (a) of another checkout (e.g. ``/work/main``) in fresh
    processes alternated with this one's, the same triples, medians compared: the θ_r = 0 path's
    cost against the code before θ_r existed.

(a), (d) and (e) are timed as the best of ``--repeat`` full runs (each takes about a second, so one
run is at the mercy of other load); (b) once, over all its triples.  The machine load
(``os.getloadavg()``) is printed before and after.  Prints its figures; asserts nothing about
time.  Examples::

    python analysis/bench_certify.py --n 10000 --seed 0 --pade-subset 1000
    python analysis/bench_certify.py --n 5000 --parts a,d        # the loops only, a minute
    python analysis/bench_certify.py --n 20000 --parts a,e --compare-with /work/main   # θ_r
"""

from __future__ import annotations

import argparse
import os
import time
import warnings
from collections.abc import Callable

import numpy as np

from stringstab.certify.api import certify_batch, check
from stringstab.certify.frequency import gain
from stringstab.params import DEFAULT_DELTA, DEFAULT_HEADWAY, DEFAULT_TAU

PADE_TOL = 1e-5
STAB_BORDER = 1e-9
SWEEP_BORDER = 1e-6
OMEGA_FLOOR = 1e-3


def python_control_verdicts(K, tau, delta, headway, order):
    """(b): Padé delay, own pole check, ``control.norm(·, 'inf')``; returns (certified, norm)."""
    import control

    num_d, den_d = control.pade(delta, order) if delta > 0 else ([1.0], [1.0])
    num_d, den_d = np.asarray(num_d, float), np.asarray(den_d, float)
    certified = np.zeros(len(K), dtype=bool)
    norms = np.full(len(K), np.inf)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for i, (kx, kv, ka) in enumerate(K):
            den = np.polymul([tau, 1.0, kv + headway * kx, kx], den_d)
            num = np.polyadd(np.polymul([kv, kx], den_d), np.polymul([ka, 0.0, 0.0], num_d))
            sys = control.tf(num, den)
            if np.all(np.real(control.poles(sys)) < 0):
                norms[i] = float(control.norm(sys, "inf"))
                certified[i] = norms[i] <= 1.0 + PADE_TOL
    return certified, norms


def sweep(K, tau, delta, headway, points, chunk=50_000):
    """(c): roots and a dense sweep; returns (decided_certified, borderline, peak, omega_max)."""
    n = len(K)
    cert = np.zeros(n, dtype=bool)
    border = np.zeros(n, dtype=bool)
    peak = np.full(n, np.inf)
    omax = np.full(n, np.nan)
    for i, (kx, kv, ka) in enumerate(K):
        c = kv + headway * kx
        re_max = np.roots([tau, 1.0, c, kx]).real.max()
        if abs(re_max) <= STAB_BORDER:
            border[i] = True
        if re_max >= 0:
            continue
        cubic = np.roots([0.5 * tau, -abs(ka), -(0.5 * abs(c) + abs(kv)), -abs(kx)])
        om = max(cubic[np.abs(cubic.imag) < 1e-12].real.max(), 1.0)
        omax[i] = om
        w = np.linspace(0.0, om, points)
        p, m = 0.0, np.inf
        for s in range(0, points, chunk):
            ws = w[s:s + chunk]
            g = gain(ws, kx, kv, ka, tau=tau, delta=delta, headway=headway)
            p = max(p, float(g.max()))
            keep = ws >= OMEGA_FLOOR
            if keep.any():
                m = min(m, float(((1.0 - g[keep] ** 2) / np.minimum(1.0, ws[keep] ** 2)).min()))
        peak[i] = p
        border[i] |= abs(m) <= SWEEP_BORDER
        cert[i] = m > 0
    return cert, border, peak, omax


def best_of(f: Callable[[], object], repeat: int) -> float:
    """The shortest of ``repeat`` timed runs of f (a warm-up run first, untimed)."""
    f()
    best = float("inf")
    for _ in range(max(repeat, 1)):
        t0 = time.perf_counter()
        f()
        best = min(best, time.perf_counter() - t0)
    return best


#: The box of (d): τ, δ, T* intervals (s).
BOX = {"tau": (0.1, 0.2), "delta": (0.15, 0.25), "headway": (1.0, 1.2)}


def other_loops(K, prm, ta, repeat, n_robust_sampled):
    """(d): per-triple cost of the sampled and robust certificates, as ratios to (a)."""
    Ks = K[:n_robust_sampled]
    cases = [
        ("continuous check (verdicts only)", lambda: check(*K.T, **prm), len(K), {}),
        ("sampled certify_batch, Δt = 0.1 s", None, len(K), {"sample_time": 0.1}),
        ("sampled check, Δt = 0.1 s", "check", len(K), {"sample_time": 0.1}),
        ("sampled certify_batch, Δt = 0.08 s (δ/Δt = 2.5)", None, len(K), {"sample_time": 0.08}),
        ("robust continuous certify_batch, box τ/δ/T*", None, len(K), BOX),
        ("robust sampled certify_batch, Δt = 0.1 s, box τ/δ/T*, heterogeneous", None, len(Ks),
         {**BOX, "sample_time": 0.1}),
    ]
    print(f"\n(d) the other loops on the same triples ({os.getloadavg()[0]:.2f} load): "
          f"ms per triple, best of {repeat}; ratio to (a)")
    print("| certificate | ms per triple | ratio to (a) certify_batch | certified | not_certified | inconclusive |")
    print("|---|---|---|---|---|---|")
    print(f"| (a) continuous certify_batch (baseline) | {ta * 1e3:.4f} | 1.00 | | | |")
    for name, f, n, kw in cases:
        k = K[:n]
        p = {**prm, **kw}
        if f is None:
            def f(k=k, p=p):
                return certify_batch(*k.T, **p)
        elif f == "check":
            def f(k=k, p=p):
                return check(*k.T, **p)
        t = best_of(f, repeat) / n
        v = f().verdict
        counts = " | ".join(str(int(np.count_nonzero(v == x)))
                            for x in ("certified", "not_certified", "inconclusive"))
        print(f"| {name} ({n} triples) | {t * 1e3:.4f} | {t / ta:.2f} | {counts} |")


#: θ_r values of (e), s.
THETAS = (0.1, 0.2, 0.5)


def reaction_part(K, prm, ta, repeat):
    """(e): the certificate with a reaction delay, per triple, as ratios to θ_r = 0."""
    # the baseline again, warmed up like the others (the first runs of (a) pay for caches)
    ta = min(ta, best_of(lambda: certify_batch(*K.T, **prm), repeat) / len(K))
    tc = best_of(lambda: check(*K.T, **prm), repeat) / len(K)
    print(f"\n(e) the reaction delay θ_r on the same triples ({os.getloadavg()[0]:.2f} load): "
          f"µs per triple, best of {repeat}")
    print("| θ_r (s) | certify_batch µs | ratio to (a) | check µs | ratio to θ_r = 0 check "
          "| certified | not_certified | inconclusive |")
    print("|---|---|---|---|---|---|---|---|")
    print(f"| 0 (a, baseline) | {ta * 1e6:.1f} | 1.00 | {tc * 1e6:.1f} | 1.00 | | | |")
    t0 = best_of(lambda: certify_batch(*K.T, **prm, reaction_delay=0.0), repeat) / len(K)
    print(f"| 0.0 given (today's path) | {t0 * 1e6:.1f} | {t0 / ta:.2f} | | | | | |")
    for th in THETAS:
        tb = best_of(lambda th=th: certify_batch(*K.T, **prm, reaction_delay=th), repeat) / len(K)
        tk = best_of(lambda th=th: check(*K.T, **prm, reaction_delay=th), repeat) / len(K)
        v = certify_batch(*K.T, **prm, reaction_delay=th).verdict
        counts = " | ".join(str(int(np.count_nonzero(v == x)))
                            for x in ("certified", "not_certified", "inconclusive"))
        print(f"| {th:g} | {tb * 1e6:.1f} | {tb / ta:.2f} | {tk * 1e6:.1f} | {tc and tk / tc:.2f} "
              f"| {counts} |")


_TIME_A = """
import sys, time, numpy as np
sys.path.insert(0, {src!r})
from stringstab.certify.api import certify_batch
K = np.random.default_rng({seed}).uniform(-2.0, 2.0, size=({n}, 3))
certify_batch([1.0], [1.0], [0.0], **{prm!r})
best = float("inf")
for _ in range({repeat}):
    t0 = time.perf_counter(); certify_batch(*K.T, **{prm!r}); best = min(best, time.perf_counter() - t0)
print(best / {n})
"""


def compare_part(other: str, args, prm) -> None:
    """(e): (a) of this checkout and of ``other``, in fresh processes, alternated."""
    import subprocess
    import sys
    from pathlib import Path

    here = str(Path(__file__).resolve().parents[1])
    runs: dict[str, list[float]] = {here: [], other: []}
    for _ in range(5):
        for src in (other, here):
            code = _TIME_A.format(src=src, seed=args.seed, n=args.n, prm=prm, repeat=args.repeat)
            out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                                 check=True)
            runs[src].append(float(out.stdout.strip().splitlines()[-1]))
    a, b = np.median(runs[here]), np.median(runs[other])
    print(f"\n(e) θ_r = 0 path against {other} ({os.getloadavg()[0]:.2f} load), certify_batch on "
          f"the same {args.n} triples, 5 alternated fresh processes, medians: this checkout "
          f"{a * 1e6:.1f} µs/triple, {other} {b * 1e6:.1f} µs/triple, ratio {a / b:.3f} "
          f"(per run: {', '.join(f'{x / y:.2f}' for x, y in zip(runs[here], runs[other]))})")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=10_000, help="number of random triples (default 10^4)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--repeat", type=int, default=3,
                    help="time (a) over this many full runs and report the best (default 3)")
    ap.add_argument("--pade-subset", type=int, default=0,
                    help="run (b) on this many random triples of the n (0: all)")
    ap.add_argument("--pade-order", type=int, default=5)
    ap.add_argument("--sweep-subset", type=int, default=0,
                    help="run the sweep (c) on this many random triples (0: all)")
    ap.add_argument("--points", type=int, default=1_000_000, help="sweep points per triple")
    ap.add_argument("--tau", type=float, default=DEFAULT_TAU)
    ap.add_argument("--delta", type=float, default=DEFAULT_DELTA)
    ap.add_argument("--headway", type=float, default=DEFAULT_HEADWAY)
    ap.add_argument("--parts", default="a,b,c,d,e",
                    help="which of (a)-(e) to run, e.g. a,d (default: all; (a) always)")
    ap.add_argument("--compare-with", metavar="DIR",
                    help="(e): also time (a) of the checkout DIR (e.g. /work/main) in alternated "
                         "fresh processes")
    ap.add_argument("--n-robust-sampled", type=int, default=500,
                    help="triples for the robust sampled certificate in (d) (default 500)")
    args = ap.parse_args(argv)
    parts = set(args.parts.split(",")) | {"a"}
    prm = {"tau": args.tau, "delta": args.delta, "headway": args.headway}

    rng = np.random.default_rng(args.seed)
    K = rng.uniform(-2.0, 2.0, size=(args.n, 3))
    print(f"# {args.n} triples K ~ U[-2, 2]^3, seed {args.seed}; "
          f"tau={args.tau}, delta={args.delta}, headway={args.headway}; "
          "load before %.2f %.2f %.2f" % os.getloadavg())

    # (a) exact batch, one run (a tiny warm-up call first so imports are not timed)
    certify_batch([1.0], [1.0], [0.0], **prm)
    times = []
    for _ in range(max(args.repeat, 1)):
        t0 = time.perf_counter()
        b = certify_batch(K[:, 0], K[:, 1], K[:, 2], **prm)
        times.append((time.perf_counter() - t0) / args.n)
    ta = min(times)
    s = b.summary()
    print(f"(a) certify_batch (exact delay): {ta * 1e6:9.1f} us/triple (best of {len(times)} "
          f"runs of all {args.n}; median {np.median(times) * 1e6:.1f})   "
          f"certified {s['certified']}, not_certified {s['not_certified']}, "
          f"inconclusive {s['inconclusive']}")

    if "d" in parts:
        other_loops(K, prm, ta, args.repeat, args.n_robust_sampled)
    if "e" in parts:
        reaction_part(K, prm, ta, args.repeat)
        if args.compare_with:
            compare_part(args.compare_with, args, prm)
    if "b" in parts:
        pade_part(K, b, ta, args, rng)
    if "c" in parts:
        sweep_part(K, b, args, rng)
    print("\nload after %.2f %.2f %.2f" % os.getloadavg())  # noqa: UP031


def pade_part(K, b, ta, args, rng):
    """(b) python-control (a warm-up call first so the import of control is not timed)."""
    python_control_verdicts(K[:1], args.tau, args.delta, args.headway, args.pade_order)
    m = args.n if args.pade_subset <= 0 else min(args.pade_subset, args.n)
    idx = np.sort(rng.choice(args.n, size=m, replace=False)) if m < args.n else np.arange(args.n)
    t0 = time.perf_counter()
    pc_cert, pc_norm = python_control_verdicts(K[idx], args.tau, args.delta, args.headway,
                                               args.pade_order)
    tb = (time.perf_counter() - t0) / m
    subset = "all" if m == args.n else f"random subset of {m}"
    print(f"(b) python-control Padé({args.pade_order}) + poles + norm('inf'): {tb * 1e6:9.1f} "
          f"us/triple ({subset}); certified {int(pc_cert.sum())} of {m}")
    print(f"    ratio (b)/(a): {tb / ta:.0f}x")
    va = b.verdict[idx]
    decided = va != "inconclusive"
    dis = decided & ((va == "certified") != pc_cert)
    print(f"    verdict disagreements (a) vs (b): {int(dis.sum())} of {int(decided.sum())} "
          f"decided by (a) ({int((~decided).sum())} inconclusive in (a))")
    for j in np.flatnonzero(dis)[:5]:
        i = idx[j]
        print(f"      K=({K[i, 0]:.6f}, {K[i, 1]:.6f}, {K[i, 2]:.6f}): (a) {va[j]} "
              f"sup {b.sup_gain[i]:.9g}, hurwitz margin {b.hurwitz_margin[i]:.3g}; "
              f"(b) norm {pc_norm[j]:.9g}")


def sweep_part(K, b, args, rng):
    """(c) independent roots + dense sweep."""
    m = args.n if args.sweep_subset <= 0 else min(args.sweep_subset, args.n)
    idx = np.sort(rng.choice(args.n, size=m, replace=False)) if m < args.n else np.arange(args.n)
    t0 = time.perf_counter()
    sw_cert, border, peak, omax = sweep(K[idx], args.tau, args.delta, args.headway, args.points)
    tc = (time.perf_counter() - t0) / m
    va = b.verdict[idx]
    ok = ~border
    dis = ok & (va != "inconclusive") & ((va == "certified") != sw_cert)
    inc = ok & (va == "inconclusive")
    unsound = (va == "certified") & (peak > 1.0 + 1e-9)
    subset = "all" if m == args.n else f"random subset of {m}"
    print(f"(c) numpy.roots + {args.points:.0e}-point sweep of |Γ(jω)| ({subset}): "
          f"{tc * 1e3:.1f} ms/triple; {int(np.isfinite(omax).sum())} Hurwitz triples swept, "
          f"the others unstable by numpy.roots")
    print(f"    borderline (|max Re pole| <= {STAB_BORDER:g} or |min (1-|Γ|²)/min(1,ω²)| <= "
          f"{SWEEP_BORDER:g}): {int(border.sum())}")
    print(f"    disagreements (a) vs sweep on the {int(ok.sum())} non-borderline triples: "
          f"{int(dis.sum())}; inconclusive in (a) among them: {int(inc.sum())}")
    print(f"    certified by (a) with swept peak > 1 + 1e-9: {int(unsound.sum())}")
    for j in np.flatnonzero(dis | inc)[:5]:
        i = idx[j]
        print(f"      K=({K[i, 0]:.6f}, {K[i, 1]:.6f}, {K[i, 2]:.6f}): (a) {va[j]} "
              f"sup {b.sup_gain[i]:.9g}; sweep peak {peak[j]:.9g}, certified {sw_cert[j]}")


if __name__ == "__main__":
    main()
