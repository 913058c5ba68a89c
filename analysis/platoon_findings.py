"""The findings of docs/platoon.md for recorded strings: verdicts, the CAV, the replays (issue 27).

For each ``identify.json`` given (the shipped OpenACC logs, written by
``stringstab identify --example acc|human --out DIR``):

1. the recorded string's head-to-tail verdict, sup ∏|Γ_i| and where, its worst sub-string,
   and the data's own first-to-last amplification (:func:`stringstab.certify.api.certify_string`,
   :func:`stringstab.mixed.empirical.string_empirical`);
2. for every position, one CAV with the default parameters (τ 0.1 s, δ 0.2 s, T* 1.1 s, gains
   in [−2, 2], k_x ≥ 0.01): the design's verdict, whether "none exists" is proven, the
   smallest sup found (:func:`stringstab.mixed.design.design_cavs`);
3. the smallest CAV time headway T* (on a grid, ``--headways``) for which a single CAV at some
   position is certified, with its position, gains and margin (the first T* of the grid at
   which the design certifies; the exclusion proof says where none exists below it);
4. the replays of the recorded leader with and without that CAV, and the probe at the
   recorded string's peak frequency (:mod:`stringstab.mixed.replay`).

Prints the tables and the machine load; asserts nothing.

Example::

    stringstab identify --example acc --out runs/acc
    stringstab identify --example human --out runs/human
    python analysis/platoon_findings.py runs/acc/identify.json runs/human/identify.json
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

from stringstab.certify.api import certify_string
from stringstab.mixed import read_vehicles
from stringstab.mixed.cav import CavSpec
from stringstab.mixed.design import design_cavs
from stringstab.mixed.empirical import string_empirical
from stringstab.mixed.replay import probe, replay


def _g(x: float, d: int = 4) -> str:
    return f"{x:.{d}g}"


def findings(path: str, headways: list[float]) -> None:
    """Print the findings of one identify.json (module docstring)."""
    t0 = time.perf_counter()
    rec = read_vehicles(path)
    names = ", ".join(f"{p}:{v.name}" for p, v in zip(rec.positions, rec.vehicles))
    print(f"\n## {path}: followers {names} behind {rec.leader}")
    if rec.note:
        print(f"note: {rec.note}")
    cert = certify_string(rec.vehicles)
    w = cert.worst_substring
    print(f"recorded string: {cert.verdict}; sup ∏|Γ_i| = {_g(cert.sup_gain)} at ω = "
          f"{_g(cert.peak_omega, 3)} rad/s; worst sub-string "
          + ("none" if w is None else f"{w.first}-{w.last} ({w.verdict}, sup {_g(w.sup_gain)})"))
    print("each vehicle: " + ", ".join(f"{c.verdict[:3]} {_g(float(c.sup_gain))}"
                                       for c in cert.certificates))
    emp = string_empirical(rec)
    e = emp.as_dict()
    print(f"the data (first -> last, {e['seconds']:.0f} s): max |Ĝ| = {_g(e['gain'])} ± "
          f"{_g(e['gain_error'], 2)} at {_g(e['omega'], 3)} rad/s (amplifies: {e['amplifies']}); "
          f"peak-to-peak {_g(e['peak_to_peak'], 3)}, energy {_g(e['energy'], 3)}")
    print("\none CAV with the defaults (T* = 1.1 s):")
    print(f"{'pos':>4} {'replaces':<18} {'verdict':<14} {'none exists':<12} {'best sup':>9}  gains")
    for p in range(1, len(rec.vehicles) + 1):
        d = design_cavs(rec.vehicles, [p])
        k = d.gains[0]
        print(f"{p:>4} {rec.vehicles[p - 1].name:<18} {d.certificate.verdict:<14} "
              f"{'proven' if d.proven_none else 'no':<12} {d.certificate.sup_gain:>9.4g}  "
              f"({k[0]:.4g}, {k[1]:.4g}, {k[2]:.4g})")
    print("\nthe smallest CAV headway T* (of the grid) with a certified single CAV:")
    best = None
    for T in headways:
        spec = CavSpec(headway=T)
        found = []
        for p in range(1, len(rec.vehicles) + 1):
            d = design_cavs(rec.vehicles, [p], spec)
            found.append((p, d))
        ok = [(p, d) for p, d in found if d.certified]
        proven = [p for p, d in found if d.proven_none]
        print(f"  T* = {T:g} s: certified at {[p for p, _ in ok] or 'none'}; none exists (proven) "
              f"at {proven or 'none'}")
        if ok:
            best = max(ok, key=lambda t: t[1].margin)
            print(f"  -> position {best[0]}, gains {tuple(round(x, 4) for x in best[1].gains[0])}, "
                  f"margin μ = {_g(best[1].margin)}, sup = {_g(best[1].certificate.sup_gain)}")
            break
    if best is None:
        print("  no single CAV on this grid")
        return
    p, d = best
    l0 = list(rec.standstill)
    l0[p - 1] = 2.0
    rp = replay(rec, [(f"CAV at {p}", d.vehicles, l0)])
    for r in rp.runs:
        print(f"replay {r.label}: energy ratio last/leader {_g(r.band_ratio, 3)} (0 < ω ≤ 1), "
              f"{_g(r.energy_ratio, 3)} (all ω); peak-to-peak {_g(r.peak_to_peak, 3)}; "
              f"band m_p {np.round(r.band_m_p, 3).tolist()}; min gap {_g(r.min_gap, 3)} m")
    pr = probe([("recorded", rec.vehicles, rec.standstill), (f"CAV at {p}", d.vehicles, l0)],
               cert.peak_omega, speed=float(np.mean(np.asarray(rp.runs[0].result.speed)[0])))
    for lab, m, q in zip(pr.labels, pr.measured, pr.predicted):
        print(f"probe ω = {pr.omega:.3g} rad/s, {lab}: simulated {_g(m)}, ∏|Γ_i(jω)| = {_g(q)}")
    print(f"({time.perf_counter() - t0:.0f} s)")


def main(argv: list[str] | None = None) -> int:
    """Print the findings of each identify.json (module docstring)."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("files", nargs="+", metavar="IDENTIFY_JSON")
    ap.add_argument("--headways", default="1.1,1.5,2,3,4,5,6,7,8,10",
                    help="CAV T* grid, s (default 1.1,1.5,2,3,4,5,6,7,8,10)")
    args = ap.parse_args(argv)
    print("# load " + " ".join(f"{x:.2f}" for x in os.getloadavg()))
    Ts = [float(x) for x in args.headways.split(",")]
    for f in args.files:
        findings(f, Ts)
    return 0


if __name__ == "__main__":
    sys.exit(main())
