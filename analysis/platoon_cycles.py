"""Certified gains in the time domain: 10- and 100-vehicle platoons on every bundled cycle.

1. The gain triple K = (1.2, 0.5, 0.6) (the ``stringstab simulate`` default and the issue's
   example) is checked at τ = 0.1 s, δ = 0.2 s, T* = 1.1 s:
   internal stability (k_x > 0 and k_v + (T* − τ) k_x > 0: Γ's denominator is a Hurwitz
   cubic), a fine sweep of |Γ(jω)| with the exact delay (:func:`stringstab.certify.frequency.gain` on
   ``--sweep`` log-spaced ω in [1e-4, 1e3] rad/s), and the exact certificate
   (:func:`stringstab.certify.api.certify`): sup_ω |Γ(jω)| = 1, reached only at ω = 0.
2. Platoons of 10 and 100 followers run behind UDDS, HWFET, US06 and WLTC 3b (Δt = 0.1 s,
   leader speed capped at 33.3 m/s) and behind the §5.1-style mixed leader, starting in
   equilibrium; the leader then holds its final speed for ``--settle`` s (300) so that the
   disturbance has left even the 100th vehicle before the sums of eq 29 are closed.  Printed: the m_p of every follower relative to its predecessor (IDL eq 29,
   intended form), max m_p, M_lss, collisions, minimum gap and TIT.
3. For contrast, the van Arem (2006) CACC gains (0.1, 0.58, 1.0) — not certified — on the
   10-vehicle platoons.

Figures (``--out``): ``<cycle>_<N>.png`` (speed, acceleration, spacing, headway of every
vehicle), ``damping_ratios.png`` (m_p per position, all runs) and ``gain_sweep.png``; plus
``summary.json``.  Example::

    python analysis/platoon_cycles.py --out out/platoon_cycles
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from stringstab.certify.api import certify
from stringstab.certify.frequency import gain
from stringstab.plots import plot_damping_ratios, plot_platoon
from stringstab.traffic import (
    CACCController,
    LinearController,
    leader_by_name,
    simulate,
)

TAU, DELTA, HEADWAY = 0.1, 0.2, 1.1
K = (1.2, 0.5, 0.6)
LEADERS = ("udds", "hwfet", "us06", "wltc3b", "mix")
SIZES = (10, 100)


def check_gains(n_sweep: int, out: Path) -> dict[str, object]:
    k_x, k_v, _ = K
    hurwitz = (k_x, k_v + (HEADWAY - TAU) * k_x)
    w = np.logspace(-4, 3, n_sweep)
    g = gain(w, *K, tau=TAU, delta=DELTA, headway=HEADWAY)
    away = w >= 1e-2
    cert = certify(*K, tau=TAU, delta=DELTA, headway=HEADWAY)
    print(f"gains K = {K} at tau={TAU}, delta={DELTA}, headway={HEADWAY}")
    print(f"  internal stability: k_x = {hurwitz[0]:g} > 0, k_v + (T*-tau) k_x = {hurwitz[1]:g} > 0")
    print(f"  sweep of |Gamma(jw)| on {n_sweep} points in [1e-4, 1e3] rad/s: max {g.max():.9f} "
          f"(at w = {w[np.argmax(g)]:.2e}); max for w >= 0.01: {g[away].max():.6f} "
          f"at w = {w[away][np.argmax(g[away])]:.3f} rad/s")
    print(f"  certificate: {cert.verdict}, sup|Gamma| = {cert.sup_gain}, min g = {cert.margin:.6g}")
    fig = Figure(figsize=(6, 3.5), layout="constrained")
    ax = fig.subplots()
    ax.semilogx(w, g, label=f"K = {K} (certified)")
    ax.semilogx(w, gain(w, 0.1, 0.58, 1.0, tau=TAU, delta=DELTA, headway=HEADWAY),
                label="van Arem CACC (0.1, 0.58, 1.0)")
    ax.axhline(1.0, color="k", ls="--", lw=0.8)
    ax.set_xlabel("ω (rad/s)")
    ax.set_ylabel("|Γ(jω)|")
    ax.legend()
    ax.grid(alpha=0.3)
    fig.savefig(out / "gain_sweep.png", dpi=110)
    return {"K": K, "hurwitz": hurwitz, "sweep_max": float(g.max()),
            "sweep_max_away_from_0": float(g[away].max()), "verdict": cert.verdict,
            "sup_gain": cert.sup_gain, "margin": cert.margin}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="out/platoon_cycles")
    ap.add_argument("--sweep", type=int, default=200_001)
    ap.add_argument("--settle", type=float, default=300.0)
    a = ap.parse_args()
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    summary: dict[str, object] = {"gains": check_gains(a.sweep, out), "runs": {}}
    runs: dict[str, dict[str, object]] = summary["runs"]  # type: ignore[assignment]
    fig_mp = Figure(figsize=(10, 4), layout="constrained")
    ax10, ax100 = fig_mp.subplots(1, 2)
    print()
    for name in LEADERS:
        lead = leader_by_name(name, dt=0.1).hold(a.settle)
        for n in SIZES:
            res = simulate(lead, LinearController(*K, headway=HEADWAY), n, tau=TAU, delta=DELTA)
            m = res.metrics()
            mp = np.asarray(m["m_p"])
            key = f"{lead.name}_{n}"
            runs[key] = {k: m[k] for k in ("m_p", "max_m_p", "M_lss", "collisions", "min_gap", "TIT",
                                            "M_CI", "M_effi", "m_fss")}
            print(f"{lead.name:>9s} N={n:<3d} max m_p = {m['max_m_p']:.4f} (vehicle {int(np.argmax(mp)) + 1}), "
                  f"M_lss = {m['M_lss']:.4f}, collisions = {m['collisions']}, "
                  f"min gap = {m['min_gap']:.2f} m, TIT = {m['TIT']:.2f}, M_fss = {m['m_fss']}%")
            print("    m_p: " + ", ".join(f"{v:.3f}" for v in mp))
            plot_damping_ratios(mp, ax=ax10 if n == 10 else ax100, label=lead.name)
            fig = Figure(figsize=(12, 7.5), layout="constrained")
            plot_platoon(res, fig=fig, title=f"{lead.name}: {n} followers, K = {K} (certified)")
            fig.savefig(out / f"{key}.png", dpi=100)
        cacc = simulate(lead, CACCController(t_system=HEADWAY), 10, tau=TAU, delta=DELTA, record=False)
        mp = cacc.damping_ratios
        runs[f"{lead.name}_10_cacc"] = {"m_p": mp.round(6).tolist(), "max_m_p": float(mp.max()),
                                        "collisions": int(cacc.collision_events.sum())}
        print(f"{lead.name:>9s} N=10  van Arem CACC (not certified): max m_p = {mp.max():.4f}, "
              f"collisions = {int(cacc.collision_events.sum())}; m_p: "
              + ", ".join(f"{v:.3f}" for v in mp))
    for ax, n in ((ax10, 10), (ax100, 100)):
        ax.set_title(f"{n} followers, K = {K}")
        ax.legend(fontsize=8)
    fig_mp.savefig(out / "damping_ratios.png", dpi=110)
    (out / "summary.json").write_text(json.dumps(summary, indent=1) + "\n")
    worst = max(r["max_m_p"] for k, r in runs.items() if not k.endswith("cacc"))
    coll = sum(r["collisions"] for k, r in runs.items() if not k.endswith("cacc"))
    print(f"\ncertified gains, all cycles and sizes: max m_p = {worst:.4f}, collisions = {coll}")
    print(f"figures and summary.json in {out}/")


if __name__ == "__main__":
    main()
