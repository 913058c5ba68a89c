"""The HCFS paper's leaders (§IV), as close as the bundled data allows.

What the paper uses
    "the velocity twice as slow of real vehicle experiment [24]" sampled at T = 0.2 s
    (Fig. 3): the DDPG trains in a platoon of six followers behind "the velocity from 600 s to
    the end"; the tests are 20 s windows of the same experiment, 200-220 s with 8 followers
    (case 1, "not included in the training data"; the leader starts at 0.37 m/s and speeds up
    to 10.76 m/s), 620-640 s with 6 (case 2) and 1020-1040 s with 4 (case 3).  The recording of
    [24] is not available, and the paper's cases 2 and 3 lie *inside* its training range.

What is used here
    The bundled EPA UDDS (a real-world urban drive, 1369 s at 1 Hz; ``stringstab/data/cycles``)
    at half speed — the paper's "twice as slow": v/2, and so a/2 and x/2 — on the 0.2 s grid.

    * Training (:func:`training_leader`): 600 s to the end (769 s, 0-7.7 m/s), as printed.
    * Tests (:data:`CASES`, :func:`case_leader`): three 20 s windows of [0, 600) s, all outside
      the training range.  At the paper's own times UDDS is cruising (200-220 s), stopped
      (620-640 s) or stopping (1020-1040 s), and the last two are training data; instead the
      three windows starting at a multiple of 20 s in [0, 580] s with the largest speed
      variation Σ|Δv| are taken (380, 180 and 440 s), the one that starts from standstill and
      speeds up (440-460 s, 0 → 7.5 m/s; the printed case 1 goes 0.37 → 10.76 m/s) as case 1 with
      8 followers, then 180-200 s with 6 (case 2) and 380-400 s with 4 (case 3).  The windows
      stay within 9.4 m/s (case 1: 0 → 7.5, case 2: 5.8 → 9.4, case 3: 8.2 → 0 m/s); the training
      range reaches 7.7 m/s, the whole half-speed UDDS 12.7 m/s.

:func:`hcfs_leader` resolves the names ``hcfs-train``, ``hcfs-case1`` … ``hcfs-case3`` and passes
anything else to :func:`stringstab.traffic.leaders.leader_by_name`.

References
----------
HCFS paper, §IV and §IV-A-C.
"""

from __future__ import annotations

import dataclasses
import math

from ..errors import StringStabError, show
from ..traffic.cycles import cycle
from ..traffic.leaders import leader_by_name
from ..traffic.trajectory import Trajectory
from .constants import DT

__all__ = [
    "CASES",
    "HALF_SPEED",
    "LEADER_NAMES",
    "TRAINING_START",
    "case_leader",
    "half_speed",
    "hcfs_leader",
    "paper_cases",
    "training_leader",
]

#: The paper's "velocity twice as slow" of its experiment: every speed is multiplied by this.
HALF_SPEED = 0.5
#: Start of the training part of the experiment, s (HCFS §IV: "from 600 s to the end").
TRAINING_START = 600.0
#: The test cases: name → (start s, end s, followers), windows of half-speed UDDS before 600 s.
CASES: dict[str, tuple[float, float, int]] = {
    "hcfs-case1": (440.0, 460.0, 8),
    "hcfs-case2": (180.0, 200.0, 6),
    "hcfs-case3": (380.0, 400.0, 4),
}
#: Every name :func:`hcfs_leader` knows besides those of ``leader_by_name``.
LEADER_NAMES = ("hcfs-train", *CASES)


def half_speed(tr: Trajectory, *, factor: float = HALF_SPEED, name: str | None = None) -> Trajectory:
    """A leader driving ``factor`` times as fast: speed, acceleration and position all scaled.

    Scaling a piecewise-linear speed keeps the trajectory exact on its grid (x_{k+1} = x_k +
    v_k T + ½ a_k T² still holds).

    Parameters
    ----------
    tr : Trajectory
        The leader.
    factor : float
        Speed factor (> 0); HCFS §IV drives "twice as slow", 0.5.
    name : str, optional
        The new name (default ``"<name> x<factor>"``).

    Returns
    -------
    Trajectory
        The scaled leader; ``meta["speed_factor"]`` records the factor.

    Raises
    ------
    StringStabError
        If ``factor`` is not a finite number > 0.

    Examples
    --------
    >>> from stringstab.traffic import from_speed
    >>> half_speed(from_speed([0, 1], [10.0, 12.0], dt=0.5)).speed.tolist()
    [5.0, 5.5, 6.0]
    """
    f = float(factor)
    if not (math.isfinite(f) and f > 0):
        raise StringStabError(f"the speed factor must be a finite number > 0; got {show(factor)}")
    return Trajectory(tr.dt, tr.position * f, tr.speed * f, tr.accel * f,
                      name or f"{tr.name} x{f:g}", {**tr.meta, "speed_factor": f})


def _udds_half(dt: float) -> Trajectory:
    return half_speed(cycle("udds", dt=dt), name="udds/2")


def _window(tr: Trajectory, start: float, stop: float | None, name: str) -> Trajectory:
    w = tr.window(round(start / tr.dt), None if stop is None else round(stop / tr.dt) + 1)
    end = stop if stop is not None else (tr.n_steps - 1) * tr.dt
    return dataclasses.replace(w, name=name, meta={**w.meta, "window_s": [start, end]})


def training_leader(*, dt: float = DT) -> Trajectory:
    """The DDPG's training leader: UDDS at half speed from 600 s to the end (HCFS §IV).

    Parameters
    ----------
    dt : float
        Frame length T, s.

    Returns
    -------
    Trajectory
        The leader, re-timed to start at t = 0.

    Examples
    --------
    >>> tr = training_leader()
    >>> tr.name, tr.duration, round(float(tr.speed.max()), 2)
    ('udds/2 600-1369 s', 769.0, 7.67)
    """
    full = _udds_half(dt)
    end = (full.n_steps - 1) * full.dt
    return _window(full, TRAINING_START, None, f"udds/2 {TRAINING_START:g}-{end:g} s")


def case_leader(name: str, *, dt: float = DT) -> tuple[Trajectory, int]:
    """A test case (see the module docstring): its leader and number of followers.

    Parameters
    ----------
    name : {"hcfs-case1", "hcfs-case2", "hcfs-case3"}
        The case (:data:`CASES`): a 20 s window of half-speed UDDS before 600 s.
    dt : float
        Frame length T, s.

    Returns
    -------
    leader : Trajectory
        The window, re-timed to start at t = 0.
    n_followers : int
        The followers of the case (8, 6, 4).

    Raises
    ------
    StringStabError
        On an unknown case name.

    Examples
    --------
    >>> tr, n = case_leader("hcfs-case1")
    >>> tr.name, tr.duration, n, round(float(tr.speed[0]), 2), round(float(tr.speed.max()), 2)
    ('hcfs-case1 (udds/2 440-460 s)', 20.0, 8, 0.0, 7.51)
    """
    if name not in CASES:
        raise StringStabError(f"unknown HCFS test case {show(name)}; expected one of {list(CASES)}")
    start, stop, n = CASES[name]
    return _window(_udds_half(dt), start, stop, f"{name} (udds/2 {start:g}-{stop:g} s)"), n


def paper_cases(*, dt: float = DT) -> list[tuple[Trajectory, int]]:
    """The three test cases, in order: ``[(leader, followers), …]`` (see :data:`CASES`).

    Parameters
    ----------
    dt : float
        Frame length T, s.

    Returns
    -------
    list of (Trajectory, int)
        :func:`case_leader` of each case.

    Examples
    --------
    >>> [(tr.duration, n) for tr, n in paper_cases()]
    [(20.0, 8), (20.0, 6), (20.0, 4)]
    """
    return [case_leader(name, dt=dt) for name in CASES]


def hcfs_leader(spec: str, *, dt: float = DT, duration: float | None = None) -> Trajectory:
    """A leader by name: ``hcfs-train``, ``hcfs-case1`` … ``hcfs-case3`` or another leader spec.

    The other specs are those of :func:`~stringstab.traffic.leaders.leader_by_name` (cycles,
    synthetic profiles, CSV files).

    Parameters
    ----------
    spec : str
        The name or spec.
    dt : float
        Step T, s.
    duration : float, optional
        Keep only the first ``duration`` seconds.

    Returns
    -------
    Trajectory
        The leader's speed profile.

    Raises
    ------
    StringStabError
        For an unknown name, a bad parameter or an unreadable file.

    Examples
    --------
    >>> hcfs_leader("hcfs-case3").duration, hcfs_leader("udds", duration=10.0).duration
    (20.0, 10.0)
    """
    key = str(spec).strip().lower()
    if key not in LEADER_NAMES:
        return leader_by_name(spec, dt=dt, duration=duration)
    tr = training_leader(dt=dt) if key == "hcfs-train" else case_leader(key, dt=dt)[0]
    return tr if duration is None else tr.head(duration)
