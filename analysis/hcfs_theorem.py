"""The HCFS jerk theorem, numerically: the counterexample search, the closed-loop sweep and the
paper-style comparison of docs/hcfs.md.

    .venv/bin/python analysis/hcfs_theorem.py                 # everything (a few minutes)
    .venv/bin/python analysis/hcfs_theorem.py --skip-search   # only the closed loop
    .venv/bin/python analysis/hcfs_theorem.py --out runs/hcfs # also write a report per platoon size
    .venv/bin/python analysis/hcfs_theorem.py --policy stand-in   # the phase-1 stand-in as a1

Part 1 (P3 dropped): an exhaustive search over all 2-frame sequences on a lattice of J T / q
satisfying P1 and P2 (start values in [−J T, J T] and steps on the lattice, every eq-12 choice
and previous choice, β = 0.5), for q = 2 … 12 (:func:`stringstab.hcfs.lattice_search`); the
smallest counterexample (smallest |a1_{k−1} − a2_{k−1}|) is printed.  The Hypothesis search is a
test: ``pytest -q -s tests/hcfs/test_hcfs_theorem.py -k hypothesis`` prints the example it finds.

Part 2: the closed loop of HCFS §IV (T = 0.2 s, 5 ms V2V delay) behind the bundled cycles,
synthetic leaders and the three held-out cases (UDDS at half speed) for N = 4, 6, 8 followers
and a range of jerk limits J, with ``--policy`` as a1 (default: the bundled DDPG).

Part 3: the paper's Tables IV-VI — CACC alone, the DDPG alone and HCFS (and the stand-in), each
limited only by the acceleration bounds (J = 2a_max/T): Σ|e_v|, Σ|jerk|, Σr, collisions, on the
held-out cases (in the training distribution) and on the full-speed leaders of part 2 with
8 followers (outside it).  Only calls the library.
"""

from __future__ import annotations

import argparse
import os
import time

from stringstab.hcfs import (
    LeaderSpeedMatcher,
    candidate,
    compare_controllers,
    comparison_markdown,
    hcfs_leader,
    lattice_search,
    paper_cases,
    verify,
    write_report,
)
from stringstab.hcfs.constants import DT, PLATOON_SIZES

LEADERS = ["udds", "hwfet", "us06", "wltc3b",
           "sinusoid:omega=0.5,amplitude=2,speed=15,duration=120", "stop-and-go",
           "acceleration", "braking:decel=-3", "hcfs-case1", "hcfs-case2", "hcfs-case3"]
JERKS = [1.0, 2.5, 5.0, 10.0, 30.0]


def lattice_summary(q: int, beta: float = 0.5) -> dict[str, float]:
    """All 2-frame sequences on the lattice (J T)/q with P1, P2; the smallest counterexample."""
    s = lattice_search(q, beta=beta)
    chk = s.check
    return {"q": q, "sequences": int(chk.step.shape[0]),
            "counterexamples": int(chk.counterexamples.sum()),
            "theorem_violations": int(chk.violations.sum()),
            "bound_violations": int(chk.bound_violations.sum()),
            "smallest_gap_over_JT": s.smallest_gap,
            "largest_step_at_smallest_over_JT": s.largest_step_at_smallest_gap,
            "max_step_over_bound": float((chk.step / chk.bound).max())}


def sweep(policy, out: str | None) -> None:
    leaders = [hcfs_leader(s, dt=DT) for s in LEADERS]
    print(f"a1 = {getattr(policy, 'label', policy)}")
    print(f"leaders: {', '.join(f'{tr.name} ({tr.duration:g} s)' for tr in leaders)}")
    smallest = None
    for n in PLATOON_SIZES:
        t0 = time.perf_counter()
        ver = verify(leaders, policy, jerk_limits=JERKS, n_followers=n)
        took = time.perf_counter() - t0
        print(f"\nN = {n} followers ({took:.1f} s, load {os.getloadavg()[0]:.2f}); ok = {ver.ok}, "
              f"violations = {len(ver.violations)}")
        print("| J | mode | max jerk | max jerk / J | frames | P3 fails | C fails | counterexamples "
              "| theorem viol. | bound viol. | max step/bound | collisions |")
        print("|---|---|---|---|---|---|---|---|---|---|---|---|")
        for J in JERKS:
            for mode in ("cacc", "policy", "paper", "safe"):
                rows = [r["totals"] for r in ver.results if r["jerk_limit"] == J and r["mode"] == mode]
                tot = {k: sum(r[k] for r in rows) for k in
                       ("frames", "P3_fails", "conclusion_fails", "counterexamples", "violations",
                        "bound_violations", "collisions")}
                mj = max(r["max_jerk"] for r in rows)
                msb = max(r["max_step_over_bound"] for r in rows)
                print(f"| {J:g} | {mode} | {mj:.3g} | {mj / J:.3g} | {tot['frames']} | "
                      f"{tot['P3_fails']} | {tot['conclusion_fails']} | {tot['counterexamples']} | "
                      f"{tot['violations']} | {tot['bound_violations']} | {msb:.6f} | {tot['collisions']} |")
        print("\nper leader, HCFS eqs 12-14: max jerk (m/s^3) for J = " + ", ".join(f"{J:g}" for J in JERKS)
              + "; P3 holds / frames at the first J; share of frames on a1")
        for tr in leaders:
            rows = [next(r["totals"] for r in ver.results if r["leader"] == tr.name
                         and r["mode"] == "paper" and r["jerk_limit"] == J) for J in JERKS]
            print(f"  {tr.name:>30s}: " + ", ".join(f"{t['max_jerk']:.3g}" for t in rows)
                  + f"; P3 {rows[0]['P3_holds']}/{rows[0]['frames']}; a1 share "
                  + ", ".join(f"{t['ddpg_share']:.2f}" for t in rows))
        sm = ver.smallest_counterexample
        if sm is not None and (smallest is None or sm.gap_prev < smallest.gap_prev):
            smallest = sm
        if out:
            d = os.path.join(out, f"N{n}")
            write_report(ver, d, figures=False,
                         command=f"analysis/hcfs_theorem.py --skip-search --out {out}")
            print(f"wrote {d}/report.md")
    if smallest is not None:
        s = smallest
        state = {(False, True): "switch at k", (True, False): "switch at k-1 (frame after a switch)",
                 (True, True): "switches at k-1 and k", (False, False): "no switch"}[(s.prev_switch, s.switch)]
        print(f"\nsmallest closed-loop counterexample: {s.leader}, N = {s.n_followers}, J = "
              f"{s.jerk_limit:g}, follower {s.vehicle}, t = {s.t:.1f} s: |a1 - a2| at k-1 = "
              f"{s.gap_prev:.3g} m/s^2, {state}, jerk {s.jerk:.6g} m/s^3 = bound "
              f"{s.bound / DT:.6g} m/s^3")


def tables(policy) -> None:
    """The paper's Tables IV-VI: in the training distribution, then outside it."""
    others = {} if getattr(policy, "is_stand_in", False) else {"stand-in": LeaderSpeedMatcher()}
    t0 = time.perf_counter()
    rows = compare_controllers(paper_cases(), policy, others=others)
    print(f"\nheld-out cases, J = 2a_max/T ({time.perf_counter() - t0:.1f} s):")
    print(comparison_markdown(rows), end="")
    full = [(hcfs_leader(s, dt=DT), 8) for s in LEADERS if not s.startswith("hcfs-")]
    rows = compare_controllers(full, policy, others=others)
    print("\nfull-speed leaders (outside the training distribution), 8 followers, J = 2a_max/T:")
    print(comparison_markdown(rows), end="")
    names = dict.fromkeys(r["controller"] for r in rows)
    print("\nsums over those leaders: " + "; ".join(
        f"{c}: Σr {sum(r['sum_reward'] for r in rows if r['controller'] == c):.1f}, collisions "
        f"{sum(r['collisions'] for r in rows if r['controller'] == c)}" for c in names))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--skip-search", action="store_true")
    ap.add_argument("--out", default=None)
    ap.add_argument("--policy", default="bundled", help="bundled (default), stand-in or a folder")
    args = ap.parse_args()
    print(f"load average {os.getloadavg()}")
    if not args.skip_search:
        print("exhaustive 2-frame lattice search (P1, P2 hold, P3 dropped, beta = 0.5):")
        for q in (2, 4, 8, 12):  # q = 12 is about 2.7·10⁶ sequences; memory grows as q⁴
            print(f"  {lattice_summary(q)}")
    policy = candidate(args.policy)
    sweep(policy, args.out)
    tables(policy)


if __name__ == "__main__":
    main()
