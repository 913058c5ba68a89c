"""Does the θ_r certificate's verdict hold on the road?  Platoons with a reaction delay behind every cycle.

For gain triples K and reaction delays θ_r, certify the loop τ ȧ = u(t − θ_r) − a (issue 25,
``stringstab.certify``) and simulate N followers with the same θ_r (the simulator's exact
two-piece update, docs/simulate.md) behind every shipped driving cycle and the §5.1 mix (held
to one length, plus 60 s), and behind a sinusoid at the certificate's peak frequency.  Prints,
per (K, θ_r): the verdict, sup |Γ(jω)| and its ω, the largest m_p (eq 29) over the platoon on
each leader, and whether "certified ⇒ no amplification (m_p ≤ 1 + 10⁻³)" and "not certified ⇒
amplification at the peak" held.  Writes ``summary.json``.

    python analysis/reaction_platoon.py --dt 0.01 --out out/reaction_platoon
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

import numpy as np

import stringstab as ss
from stringstab.traffic import LinearController, cycle, paper_mix, simulate, sinusoid

TAU, DELTA, HEADWAY = 0.1, 0.2, 1.1
TRIPLES = [(1.2, 0.5, 0.6), (0.9, 0.7, 0.2), (1.0, 1.0, 0.3), (0.5, 1.2, 0.4)]
THETAS = [0.1, 0.2, 0.3]
LEADERS = ("udds", "hwfet", "us06", "wltc_3b", "mix")


def main(argv: list[str] | None = None) -> int:
    """Run the comparison and print its table.

    Parameters
    ----------
    argv : list of str, optional
        ``--dt``, ``--followers``, ``--out``.

    Returns
    -------
    int
        0 when every certified case stayed at or below 1 + 10⁻³ and every case not certified
        amplified at its peak frequency, 1 otherwise.
    """
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dt", type=float, default=0.01, help="simulation step, s (default 0.01)")
    ap.add_argument("--followers", type=int, default=10, help="followers (default 10)")
    ap.add_argument("--out", default="out/reaction_platoon", help="output folder")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    dt = args.dt
    cases = []
    for K in TRIPLES:
        for th in THETAS:
            c = ss.certify(*K, tau=TAU, delta=DELTA, headway=HEADWAY, reaction_delay=th)
            cases.append({"K": K, "theta_r": th, "verdict": str(c.verdict), "sup_gain": c.sup_gain,
                          "peak_omega": c.peak_omega})
    leaders = [cycle(n, dt=dt) if n != "mix" else paper_mix(dt=dt) for n in LEADERS]
    n = max(tr.n_steps for tr in leaders)
    leaders = [tr.hold((n - tr.n_steps) * dt + 60.0) for tr in leaders]
    P = len(cases) * len(leaders)
    G = np.repeat(np.array([c["K"] for c in cases]), len(leaders), axis=0)[:, None, :]
    theta = np.repeat([c["theta_r"] for c in cases], len(leaders))[:, None]
    ctrl = LinearController(G[..., 0], G[..., 1], G[..., 2], headway=HEADWAY)
    res = simulate(leaders * len(cases), ctrl, args.followers, tau=TAU, delta=DELTA,
                   reaction_delay=theta, record=False, progress=False)
    worst = res.damping_ratios.max(axis=1).reshape(len(cases), len(leaders))
    # a sinusoid at each case's peak frequency (ω of sup |Γ|; 1 rad/s where sup |Γ| is at 0)
    sines = [sinusoid(omega=float(c["peak_omega"]) if c["peak_omega"] else 1.0, amplitude=0.3,
                      speed=20.0, duration=120.0, dt=dt) for c in cases]
    Gs = np.array([c["K"] for c in cases])[:, None, :]
    rs = simulate(sines, LinearController(Gs[..., 0], Gs[..., 1], Gs[..., 2], headway=HEADWAY),
                  args.followers, tau=TAU, delta=DELTA,
                  reaction_delay=np.array([c["theta_r"] for c in cases])[:, None], record=False,
                  progress=False)
    peak = rs.damping_ratios.max(axis=1)
    ok = True
    print(f"τ = {TAU} s, δ = {DELTA} s, T* = {HEADWAY} s, Δt = {dt:g} s, {args.followers} followers, "
          f"{P} platoons behind {', '.join(LEADERS)} (held to {leaders[0].duration:g} s)")
    print(f"{'K':>16} {'θ_r':>5} {'verdict':>14} {'sup|Γ|':>7} {'ω_peak':>7} "
          + " ".join(f"{n:>8}" for n in LEADERS) + f" {'at peak':>8}  holds")
    for c, w, pk in zip(cases, worst, peak):
        if c["verdict"] == "certified":
            holds = bool(w.max() <= 1 + 1e-3)
        elif c["verdict"] == "not_certified":
            holds = bool(pk > 1.0)
        else:
            holds = True
        ok &= holds
        c.update({"max_m_p": dict(zip(LEADERS, w.round(4).tolist())), "max_m_p_at_peak": round(float(pk), 4),
                  "holds": holds})
        sup = "inf" if c["sup_gain"] is None else f"{c['sup_gain']:.3f}"
        print(f"{c['K']!s:>16} {c['theta_r']:5.2f} {c['verdict']:>14} {sup:>7} "
              f"{(c['peak_omega'] or 0):7.3f} " + " ".join(f"{v:8.4f}" for v in w) + f" {pk:8.4f}  {holds}")
    elapsed = time.perf_counter() - t0
    print(f"{'every verdict held' if ok else 'SOME VERDICT DID NOT HOLD'}; {elapsed:.1f} s, "
          f"load {os.getloadavg()[0]:.1f}")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "summary.json").write_text(json.dumps(
        {"tau": TAU, "delta": DELTA, "headway": HEADWAY, "dt": dt, "followers": args.followers,
         "cases": cases, "all_held": ok, "seconds": elapsed}, indent=1, default=str) + "\n",
        encoding="utf-8")
    return 0 if ok else 1


if __name__ == "__main__":
    raise SystemExit(main())
