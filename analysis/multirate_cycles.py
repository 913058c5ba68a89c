"""Certified multi-rate gains behind the shipped real cycles, radio on, no loss (issue 26, Done when).

For each setting (H, N, δ) — the controller and radar every H, the predecessor's acceleration
by message every N·H, held, δ late — seeded gain triples certified by the multi-rate
certificate (:func:`stringstab.certify.api.check` with ``message_period``) are simulated
(:func:`stringstab.traffic.simulate`, step Δt = H, ``Radio(message_period=N·H)``, no loss, no
noise, the exact fractional delay) in a 10-follower platoon behind every shipped leader: the
four driving cycles of ``stringstab/data/cycles`` and the leaders of the two OpenACC logs of
``stringstab/data/openacc``.  The gains: ``--random`` certified triples drawn from the test
ranges, and ``--near`` near the boundary (a certified triple whose k_a + 0.01 is not
certified: k_a raised in steps of 0.01 from a certified triple until the next step fails).

The leader's speed is raised by ``--offset`` m/s (default 20) so that no follower reaches the
speed floor 0 at the cycles' stops; in this linear loop a constant speed offset changes no
deviation from equilibrium (what the certificate bounds), and the script checks that no limit
was reached (the limits are the widest the simulator accepts: speeds in [0, 70] m/s,
accelerations within ±15 m/s²).  Reported per setting and leader, over the gains:

* ``u-link``: the largest ‖u_i‖₂/‖u_{i−1}‖₂, i = 2 … 10, over the whole run — the ℓ2 gain
  the certificate bounds by 1 (docs/sampled.md §9.2; on any finite horizon too, the link
  being causal);
* ``m_p``: the largest m_p (IDL eq 29, ‖a_i‖/‖a_{i−1}‖ of the accelerations) over i = 2 … 10
  and, separately, of follower 1 behind the leader — not certified (the a-link is not the
  u-link for N ≥ 2), measured;
* ``a/u1``: the largest ‖a_i‖₂/‖u_1‖₂ (≤ 1 at the samples by the certificate, §9.2).

The simulation integrates the lag exactly between samples (the model of the certificate), so
"≤ 1" is checked against 1 + 10⁻⁹ (round-off).  Prints a markdown table; asserts nothing.

    python analysis/multirate_cycles.py                     # ~10 CPU-min
    python analysis/multirate_cycles.py --random 2 --near 1 --leaders us06
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np

from stringstab.certify.api import check
from stringstab.identify.logs import example_log, read_logs
from stringstab.traffic import Limits, LinearController, Radio, cycle, simulate
from stringstab.traffic.trajectory import Trajectory, from_speed

TAU, HEADWAY = 0.1, 1.1
#: (H, N, δ): 10 Hz and 5 Hz messages at 100 Hz control, 5 Hz at 10 Hz, 5 Hz at 20 Hz, and a
#: fractional delay (6.5 steps) with 10 Hz messages at 50 Hz control
SETTINGS = [(0.01, 10, 0.2), (0.01, 20, 0.2), (0.1, 2, 0.2), (0.05, 4, 0.15), (0.02, 5, 0.13)]
CYCLES = ("udds", "hwfet", "us06", "wltc3b")
LOGS = ("acc", "human")
TOL = 1e-9
WIDE = Limits(accel_min=-15.0, accel_max=15.0, speed_min=0.0, speed_max=70.0)


def leaders(dt: float, offset: float, names: list[str]) -> dict[str, Trajectory]:
    """The shipped leaders at step ``dt``, speed raised by ``offset`` m/s."""
    out = {}
    for name in names:
        if name in CYCLES:
            c = cycle(name, dt=1.0, speed_max=None)
            t, v = np.arange(c.speed.size) * c.dt, c.speed
        else:
            log = read_logs(example_log(name))[0]
            t, v = log.t - log.t[0], np.maximum(log.speed[0], 0.0)
        out[name] = from_speed(t, v + offset, dt=dt, name=name)
    return out


def gains(H: float, N: int, delta: float, n_random: int, n_near: int,
          rng: np.random.Generator) -> np.ndarray:
    """Certified triples: ``n_random`` random ones and ``n_near`` at the boundary in k_a."""
    kw = dict(tau=TAU, delta=delta, headway=HEADWAY, sample_time=H, message_period=N * H)
    K = np.stack([rng.uniform(0.05, 2.0, 400), rng.uniform(-0.5, 2.0, 400),
                  rng.uniform(-0.5, 1.2, 400)], axis=1)
    cert = K[np.asarray(check(*K.T, **kw).verdict) == "certified"]
    pick = cert[rng.permutation(len(cert))]
    out = list(pick[:n_random])
    for k in pick[n_random:n_random + n_near]:
        ka = k[2] + 0.01 * np.arange(0, 171)
        ka = ka[ka <= 1.2]
        v = np.asarray(check(np.full(ka.size, k[0]), np.full(ka.size, k[1]), ka, **kw).verdict)
        bad = np.flatnonzero(v != "certified")
        if bad.size and bad[0] > 0:  # the last certified before the first failure
            out.append(np.array([k[0], k[1], ka[bad[0] - 1]]))
    return np.array(out)


def measure(K: np.ndarray, lead: Trajectory, H: float, N: int, delta: float) -> dict[str, float]:
    """Simulate the platoons of ``K`` behind ``lead``; the ratios of the module docstring."""
    P = len(K)
    ctl = LinearController(K[:, 0:1], K[:, 1:2], K[:, 2:3], headway=HEADWAY)
    res = simulate([lead] * P, ctl, 10, tau=TAU, delta=delta, limits=WIDE,
                   fractional_delay="exact", radio=Radio(message_period=N * H))
    u, a, v = res.command, res.accel[:, 1:], res.speed[:, 1:]
    nu = np.sqrt((u ** 2).sum(axis=-1))
    na = np.sqrt((a ** 2).sum(axis=-1))
    hit = bool((v <= WIDE.speed_min + 1e-9).any() or (v >= WIDE.speed_max - 1e-9).any()
               or (np.abs(a) >= 15.0 - 1e-9).any())
    mp = res.damping_ratios
    return {"u_link": float((nu[:, 1:] / nu[:, :-1]).max()), "mp": float(mp[:, 1:].max()),
            "mp1": float(mp[:, 0].max()), "a_u1": float((na / nu[:, :1]).max()),
            "limit": hit}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--random", type=int, default=4)
    ap.add_argument("--near", type=int, default=3)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--offset", type=float, default=20.0)
    ap.add_argument("--leaders", default=",".join(CYCLES + LOGS))
    a = ap.parse_args()
    names = a.leaders.split(",")
    rng = np.random.default_rng(a.seed)
    t0 = time.perf_counter()
    print(f"tau = {TAU} s, T* = {HEADWAY} s, 10 followers, seed {a.seed}, leader speed + "
          f"{a.offset:g} m/s; load {os.getloadavg()}")
    print("| H (s) | N | message period (s) | δ (s) | gains (random + near the boundary) | leader "
          "| max u-link ‖u_i‖/‖u_{i−1}‖ | max m_p (i ≥ 2) | max m_p (follower 1) | max ‖a_i‖/‖u_1‖ "
          "| limit reached |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    worst = 0.0
    for H, N, delta in SETTINGS:
        K = gains(H, N, delta, a.random, a.near, rng)
        kdesc = "; ".join(f"({k[0]:.3f}, {k[1]:.3f}, {k[2]:.3f})" for k in K)
        for name, lead in leaders(H, a.offset, names).items():
            r = measure(K, lead, H, N, delta)
            worst = max(worst, r["u_link"], r["a_u1"])
            print(f"| {H:g} | {N} | {N * H:g} | {delta:g} | {len(K)}: {kdesc} | {name} | "
                  f"{r['u_link']:.6f} | {r['mp']:.6f} | {r['mp1']:.6f} | {r['a_u1']:.6f} | "
                  f"{'yes' if r['limit'] else 'no'} |", flush=True)
            kdesc = "″"
    print(f"largest certified quantity (u-link, ‖a_i‖/‖u_1‖): {worst:.9f} "
          f"({'≤' if worst <= 1 + TOL else '>'} 1 + {TOL:g}); "
          f"{time.perf_counter() - t0:.0f} s; load {os.getloadavg()}")


if __name__ == "__main__":
    main()
