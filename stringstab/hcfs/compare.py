"""The paper-style comparison of CACC alone, the DDPG alone and HCFS (HCFS Tables IV-VI).

For each test case (a leader and a number of followers), every controller drives the platoon
of HCFS §IV (:func:`~stringstab.hcfs.verify.verify`, each candidate limited only by the
acceleration bounds: J = 2a_max/T, which no bounded action can exceed) and the sums the paper
reports are taken over all followers and frames:

* Σ|e_v|: |v_i − v_0| (the speed error to the leader, eq 4), m/s;
* Σ|jerk|: |a_k − a_{k−1}|/T of the command, m/s³;
* Σr: the eq-6 rewards earned;

with what the paper does not report: collisions, the smallest gap (the HCFS reward has no
spacing term), the largest jerk and, for HCFS, the share of frames on the learned candidate.

The paper's tables are lost in the text; only the case-1 sums survive in its prose
(:data:`PAPER_CASE1`), for a leader, a DDPG and a CACC tuning that cannot be reproduced.

References
----------
HCFS paper, §IV-A-C and Tables IV-VI.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from ..traffic.trajectory import Trajectory
from .constants import BETA, PAPER_JERK_LIMIT
from .policy import AccelerationPolicy
from .verify import verify

__all__ = ["COLUMNS", "PAPER_CASE1", "compare_controllers", "comparison_markdown"]

#: Columns of a comparison row besides the case and the controller.
COLUMNS = ("sum_abs_speed_error", "sum_abs_jerk", "sum_reward", "max_jerk", "collisions",
           "min_gap", "ddpg_share")

#: HCFS paper, case 1 (8 followers), as printed in §IV-A: (Σ|e_v| m/s, Σ|jerk| m/s³, Σr).
PAPER_CASE1: dict[str, tuple[float, float, float]] = {
    "CACC": (159.39, 720.06, -59.70),
    "DDPG": (146.22, 2344.60, -56.81),
    "HCFS": (25.26, 192.19, -9.64),
}


def _row(leader: Trajectory, n: int, controller: str, totals: Mapping[str, Any]) -> dict[str, Any]:
    return {"case": leader.name, "n_followers": n, "controller": controller,
            **{k: totals[k] for k in COLUMNS}}


def compare_controllers(cases: Sequence[tuple[Trajectory, int]], policy: AccelerationPolicy, *,
                        name: str = "DDPG", others: Mapping[str, AccelerationPolicy] | None = None,
                        jerk_limit: float = PAPER_JERK_LIMIT, beta: float = BETA) -> list[dict[str, Any]]:
    """CACC alone, ``policy`` alone and HCFS on each case; optionally other policies too.

    Parameters
    ----------
    cases : sequence of (Trajectory, int)
        Leaders and numbers of followers (e.g. :func:`~stringstab.hcfs.leaders.paper_cases`).
    policy : AccelerationPolicy
        The learned candidate a1.
    name : str
        Its name in the rows (``"DDPG"``); HCFS with it is ``"HCFS"``.
    others : mapping of str to AccelerationPolicy, optional
        Further candidates (e.g. ``{"stand-in": LeaderSpeedMatcher()}``): rows ``name`` (alone)
        and ``"HCFS (name)"``.
    jerk_limit : float
        J of the rate limit on each candidate, m/s³ (default 2a_max/T: no limit beyond the
        acceleration bounds, as in the paper's comparison).
    beta : float
        β at a switch (eq 14).

    Returns
    -------
    list of dict
        One row per case and controller: ``case``, ``n_followers``, ``controller`` and
        :data:`COLUMNS`.

    Examples
    --------
    >>> from stringstab.hcfs.leaders import paper_cases
    >>> from stringstab.hcfs.policy import LeaderSpeedMatcher
    >>> rows = compare_controllers(paper_cases()[2:], LeaderSpeedMatcher(), name="stand-in")
    >>> [r["controller"] for r in rows]
    ['CACC', 'stand-in', 'HCFS']
    """
    pols = {name: policy, **(others or {})}
    rows: list[dict[str, Any]] = []
    for leader, n in cases:
        for i, (nm, pol) in enumerate(pols.items()):
            modes = ("cacc", "policy", "paper") if i == 0 else ("policy", "paper")
            ver = verify([leader], pol, jerk_limits=[jerk_limit], n_followers=n, beta=beta, modes=modes)
            label = {"cacc": "CACC", "policy": nm, "paper": "HCFS" if i == 0 else f"HCFS ({nm})"}
            rows += [_row(leader, n, label[r["mode"]], r["totals"]) for r in ver.results]
    return rows


def comparison_markdown(rows: Sequence[Mapping[str, Any]]) -> str:
    """The rows of :func:`compare_controllers` as a Markdown table.

    Parameters
    ----------
    rows : sequence of mapping
        Rows of :func:`compare_controllers`: ``case``, ``n_followers``, ``controller``,
        ``sum_abs_speed_error`` (Σ|e_v|, m/s), ``sum_abs_jerk`` (Σ|jerk|, m/s³), ``sum_reward``
        (Σr of eq 6), ``max_jerk`` (m/s³), ``collisions``, ``min_gap`` (m) and ``ddpg_share``
        (share of frames on a1, shown for the HCFS rows only).

    Returns
    -------
    str
        The table (header, separator, one line per row), ending in a newline.

    Examples
    --------
    >>> print(comparison_markdown([{"case": "c", "n_followers": 4, "controller": "CACC",
    ...     "sum_abs_speed_error": 1.0, "sum_abs_jerk": 2.0, "sum_reward": -0.5, "max_jerk": 1.5,
    ...     "collisions": 0, "min_gap": 4.2, "ddpg_share": 0.0}]).splitlines()[2])
    | c | 4 | CACC | 1.000 | 2.000 | -0.5000 | 1.500 | 0 | 4.20 | — |
    """
    lines = ["| case | N | controller | Σ\\|e_v\\| (m/s) | Σ\\|jerk\\| (m/s³) | Σr | max jerk (m/s³) "
             "| collisions | min gap (m) | share on a1 |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        share = "—" if r["controller"] == "CACC" or not r["controller"].startswith("HCFS") \
            else f"{r['ddpg_share']:.2f}"
        lines.append(f"| {r['case']} | {r['n_followers']} | {r['controller']} | "
                     f"{r['sum_abs_speed_error']:.3f} | {r['sum_abs_jerk']:.3f} | {r['sum_reward']:.4f} | "
                     f"{r['max_jerk']:.3f} | {r['collisions']} | {r['min_gap']:.2f} | {share} |")
    return "\n".join(lines) + "\n"
