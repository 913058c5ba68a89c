"""The HCFS jerk theorem as a checkable statement, and the bound that holds without its last premise.

The theorem (HCFS paper, §III-C) and its premises, at every frame k ≥ 1, with L = J T:

* P1: |a1_k − a1_{k−1}| ≤ L (the DDPG candidate respects the jerk limit J);
* P2: |a2_k − a2_{k−1}| ≤ L (the CACC candidate does);
* P3: a1_{k−1} = a2_{k−1} ("under the framework of HCFS", used in the proof's eq 19);
* conclusion C: |a_k − a_{k−1}| ≤ L for the hybrid output a of eqs 13-14.

Here a_{k−1} is the hybrid output of the previous frame, which after a soft switch is
β a1 + (1 − β) a2 (0.5 (a1 + a2) at β = 0.5), neither a1_{k−1} nor a2_{k−1}.  With λ_k the
weight of a1 in a_k (:func:`stringstab.hcfs.switching.switch_weights`) the identity

    a_k − a_{k−1} = λ_k (a1_k − a1_{k−1}) + (1 − λ_k)(a2_k − a2_{k−1})
                    + (λ_k − λ_{k−1}) (a1_{k−1} − a2_{k−1})

gives what really holds (proved in ``docs/hcfs.md``): under P1 and P2 alone

    |a_k − a_{k−1}| ≤ J T + |λ_k − λ_{k−1}| · |a1_{k−1} − a2_{k−1}|,

with equality attainable (:func:`tight_example`), and under eqs 13-14 |λ_k − λ_{k−1}| is 0
(no switch at k − 1 or k), 1 − β (a switch at k), β (the frame after a switch — a case the
paper's proof does not treat) or |1 − 2β| (switches at both) (:func:`weight_change`).  P3 makes
the second term vanish, so the theorem is true; without P3 it fails for every
a1_{k−1} ≠ a2_{k−1} at a switch or just after one.

Floating point: every inequality is read up to ``tol`` (default 10⁻⁹ m/s², ≈ 3·10⁻¹⁰ a_max),
far above rounding (≈ 10⁻¹⁵) and far below anything physical.  Premises P1, P2 allow L + tol
and P3 allows |a1 − a2| ≤ tol, so by the bound the conclusion is checked as ≤ L + 2 tol.

References
----------
HCFS paper, §III-C: eqs 13-14, the theorem, and its proof (eqs 15-21).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError
from ..params import positive
from .constants import BETA, DT
from .switching import check_beta, switch_weights

__all__ = [
    "DEFAULT_TOL",
    "LatticeSearch",
    "TheoremCheck",
    "check_jerk_limit",
    "check_theorem",
    "jerk_bound",
    "lattice_search",
    "tight_example",
    "weight_change",
]

Array = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]

#: Tolerance of every inequality, m/s² (see the module docstring).
DEFAULT_TOL = 1e-9

Case = Literal["switch", "after-switch", "double-switch"]


def check_jerk_limit(jerk_limit: Any) -> float:
    """J as a float: a finite number > 0 (m/s³).

    Parameters
    ----------
    jerk_limit : object
        The jerk limit J of the HCFS theorem (§III-C), m/s³.

    Returns
    -------
    float
        J.

    Raises
    ------
    StringStabError
        Unless J is a finite number > 0.

    Examples
    --------
    >>> check_jerk_limit(0)
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: jerk limit J must be a finite number > 0 m/s^3; got 0
    """
    return positive("jerk limit J", jerk_limit, unit=" m/s^3")


def weight_change(prev_switch: npt.ArrayLike, switch: npt.ArrayLike, beta: float = BETA) -> Array:
    """|λ_k − λ_{k−1}| under eqs 13-14, from the switch states α_{k−1} and α_k.

    ======================  ==========  ============
    α_{k−1} (switch at k−1)  α_k          |λ_k − λ_{k−1}|
    ======================  ==========  ============
    no                       no           0
    yes                      no           β
    no                       yes          1 − β
    yes                      yes          |1 − 2β|
    ======================  ==========  ============

    Parameters
    ----------
    prev_switch : bool array_like
        α_{k−1}: a switch at frame k − 1.
    switch : bool array_like
        α_k: a switch at frame k.
    beta : float
        β of eqs 13-14, in [0, 1].

    Returns
    -------
    array
        |λ_k − λ_{k−1}|, the factor of |a1_{k−1} − a2_{k−1}| in the jerk bound.

    Raises
    ------
    StringStabError
        If β is not in [0, 1].

    Examples
    --------
    >>> weight_change([False, True, False, True], [False, False, True, True], 0.5).tolist()
    [0.0, 0.5, 0.5, 0.0]
    """
    b = check_beta(beta)
    p = np.asarray(prev_switch, dtype=bool)
    s = np.asarray(switch, dtype=bool)
    return np.asarray(np.where(s, np.where(p, abs(1.0 - 2.0 * b), 1.0 - b), np.where(p, b, 0.0)))


def jerk_bound(jerk_limit: float, gap: npt.ArrayLike, prev_switch: npt.ArrayLike,
               switch: npt.ArrayLike, *, beta: float = BETA, dt: float = DT) -> Array:
    """The largest |a_k − a_{k−1}| possible under P1 and P2 alone (P3 dropped).

    J T + |λ_k − λ_{k−1}| · |a1_{k−1} − a2_{k−1}|, with |λ_k − λ_{k−1}| from
    :func:`weight_change`.  It is a supremum that is attained (:func:`tight_example`).

    Parameters
    ----------
    jerk_limit : float
        J, m/s³.
    gap : array_like
        a1_{k−1} − a2_{k−1}, m/s².
    prev_switch, switch : bool array_like
        α_{k−1} and α_k.
    beta, dt : float
        β (eq 13) and T.

    Returns
    -------
    ndarray
        The bound on |a_k − a_{k−1}|, m/s² per step.

    Examples
    --------
    >>> float(jerk_bound(5.0, 0.4, False, True, beta=0.5, dt=0.2))
    1.2
    """
    L = check_jerk_limit(jerk_limit) * positive("dt", dt, unit=" s")
    return np.asarray(L + weight_change(prev_switch, switch, beta) * np.abs(np.asarray(gap, dtype=np.float64)))


@dataclass(frozen=True)
class TheoremCheck:
    """The theorem's premises and conclusion evaluated at every transition k − 1 → k.

    All arrays have shape ``(..., K − 1)``: entry j is the transition into frame j + 1 of the
    sequences given to :func:`check_theorem`.

    Attributes
    ----------
    jerk_limit, dt, beta, tol : float
        J (m/s³), T (s), β and the tolerance (m/s²).
    step : array
        |a_k − a_{k−1}| of the hybrid output, m/s².
    step_ddpg, step_cacc : array
        |a1_k − a1_{k−1}| and |a2_k − a2_{k−1}|, m/s².
    gap_prev : array
        |a1_{k−1} − a2_{k−1}|, m/s².
    weight_change : array
        |λ_k − λ_{k−1}| of the weights actually applied.
    switch, prev_switch : bool array
        α_k and α_{k−1} (eq 14).
    """

    jerk_limit: float
    dt: float
    beta: float
    tol: float
    step: Array
    step_ddpg: Array
    step_cacc: Array
    gap_prev: Array
    weight_change: Array
    switch: BoolArray
    prev_switch: BoolArray

    @property
    def step_limit(self) -> float:
        """L = J T, m/s²."""
        return self.jerk_limit * self.dt

    @property
    def rate_ddpg(self) -> BoolArray:
        """P1: |a1_k − a1_{k−1}| ≤ J T."""
        return np.asarray(self.step_ddpg <= self.step_limit + self.tol)

    @property
    def rate_cacc(self) -> BoolArray:
        """P2: |a2_k − a2_{k−1}| ≤ J T."""
        return np.asarray(self.step_cacc <= self.step_limit + self.tol)

    @property
    def equal_prev(self) -> BoolArray:
        """P3: a1_{k−1} = a2_{k−1}."""
        return np.asarray(self.gap_prev <= self.tol)

    @property
    def premises(self) -> BoolArray:
        """P1 ∧ P2 ∧ P3."""
        return self.rate_ddpg & self.rate_cacc & self.equal_prev

    @property
    def conclusion(self) -> BoolArray:
        """C: |a_k − a_{k−1}| ≤ J T."""
        return np.asarray(self.step <= self.step_limit + 2.0 * self.tol)

    @property
    def bound(self) -> Array:
        """J T + |λ_k − λ_{k−1}| |a1_{k−1} − a2_{k−1}|, m/s²."""
        return np.asarray(self.step_limit + self.weight_change * self.gap_prev)

    @property
    def within_bound(self) -> BoolArray:
        """|a_k − a_{k−1}| ≤ :attr:`bound`."""
        return np.asarray(self.step <= self.bound + 2.0 * self.tol)

    @property
    def violations(self) -> BoolArray:
        """Frames where all premises hold and the conclusion fails (the theorem would be false)."""
        return self.premises & ~self.conclusion

    @property
    def bound_violations(self) -> BoolArray:
        """Frames where P1 and P2 hold and the bound fails (the bound would be false)."""
        return self.rate_ddpg & self.rate_cacc & ~self.within_bound

    @property
    def counterexamples(self) -> BoolArray:
        """Frames where P1 and P2 hold, P3 fails, and the conclusion fails."""
        return self.rate_ddpg & self.rate_cacc & ~self.equal_prev & ~self.conclusion

    @property
    def max_jerk(self) -> float:
        """max |a_k − a_{k−1}| / T over all frames, m/s³."""
        return float(self.step.max()) / self.dt if self.step.size else 0.0

    def counts(self, index: Any = ...) -> dict[str, int]:
        """Numbers of frames where each premise holds or fails, and of failures.

        ``index`` selects part of the leading axes (e.g. one vehicle); default all frames.

        Parameters
        ----------
        index : index expression, optional
            Applied to every per-frame array before counting (default ``...``: everything).

        Returns
        -------
        dict of str to int
            ``frames``, ``P1_holds``/``P1_fails``, ``P2_holds``/``P2_fails``,
            ``P3_holds``/``P3_fails``, ``premises_hold``, ``conclusion_fails``, ``violations``
            (premises hold, conclusion fails), ``counterexamples`` (P1, P2 hold, P3 and the
            conclusion fail), ``bound_violations`` and ``switches``.

        Examples
        --------
        >>> c = check_theorem([0.0, 1.0], [0.0, 1.0], [False, True], jerk_limit=5.0, dt=0.2)
        >>> c.counts()["frames"], c.counts()["violations"]
        (1, 0)
        """
        n = int(self.step[index].size)

        def cnt(a: BoolArray) -> int:
            return int(np.count_nonzero(a[index]))

        return {
            "frames": n,
            "P1_holds": cnt(self.rate_ddpg), "P1_fails": n - cnt(self.rate_ddpg),
            "P2_holds": cnt(self.rate_cacc), "P2_fails": n - cnt(self.rate_cacc),
            "P3_holds": cnt(self.equal_prev), "P3_fails": n - cnt(self.equal_prev),
            "premises_hold": cnt(self.premises),
            "conclusion_fails": n - cnt(self.conclusion),
            "violations": cnt(self.violations),
            "counterexamples": cnt(self.counterexamples),
            "bound_violations": cnt(self.bound_violations),
            "switches": cnt(self.switch),
        }


def _frames(name: str, x: npt.ArrayLike) -> Array:
    a = np.asarray(x, dtype=np.float64)
    if a.ndim < 1 or a.shape[-1] < 2:
        raise StringStabError(f"{name} must have a frame axis of length >= 2 (..., K); got shape {a.shape}")
    if not np.isfinite(a).all():
        raise StringStabError(f"{name} must be finite; found NaN or inf")
    return a


def check_theorem(
    a1: npt.ArrayLike,
    a2: npt.ArrayLike,
    use_ddpg: npt.ArrayLike,
    *,
    jerk_limit: float,
    dt: float = DT,
    beta: float = BETA,
    initial: npt.ArrayLike = False,
    output: npt.ArrayLike | None = None,
    tol: float = DEFAULT_TOL,
) -> TheoremCheck:
    """Evaluate the jerk theorem's premises and conclusion at every frame.

    Parameters
    ----------
    a1, a2 : array_like (..., K)
        The DDPG (a1) and CACC (a2) candidate accelerations of frames 0 … K − 1, m/s².
    use_ddpg : bool array_like (..., K)
        The eq-12 choices c_k (True: DDPG wins).
    jerk_limit : float
        J, m/s³ (> 0, finite).
    dt : float
        T, s.
    beta : float
        β at a switch (eqs 13-14).
    initial : bool
        The choice before frame 0 (False: CACC).
    output : array_like (..., K), optional
        The hybrid output actually applied (e.g. by the jerk-safe variant); by default the
        eq-13 output λ_k a1_k + (1 − λ_k) a2_k.  Its weights are recovered as
        (a − a2)/(a1 − a2) where a1 and a2 differ by more than ``tol``.
    tol : float
        Tolerance of every inequality, m/s².

    Returns
    -------
    TheoremCheck
        Transitions 1 … K − 1 (frame 0 has no predecessor).

    Raises
    ------
    StringStabError
        On a non-positive or non-finite J, β outside [0, 1], shapes that differ, or NaN.

    References
    ----------
    HCFS paper, §III-C (the theorem, eqs 13-21).

    Examples
    --------
    Without P3 the conclusion fails at a soft switch:

    >>> c = check_theorem([0.4, 1.4], [0.0, 1.0], [False, True], jerk_limit=5.0, dt=0.2)
    >>> bool(c.premises[0]), bool(c.conclusion[0]), round(float(c.step[0]), 6), float(c.bound[0])
    (False, False, 1.2, 1.2)
    """
    J = check_jerk_limit(jerk_limit)
    T = positive("dt", dt, unit=" s")
    b = check_beta(beta)
    t = positive("tol", tol, allow_zero=True)
    x1, x2 = _frames("a1", a1), _frames("a2", a2)
    c = np.asarray(use_ddpg, dtype=bool)
    if not (x1.shape == x2.shape == c.shape):
        raise StringStabError(
            f"a1, a2 and use_ddpg must have one shape (..., K); got {x1.shape}, {x2.shape}, {c.shape}"
        )
    lam, alpha = switch_weights(c, beta=b, initial=initial)
    if output is None:
        out = lam * x1 + (1.0 - lam) * x2
    else:
        out = _frames("output", output)
        if out.shape != x1.shape:
            raise StringStabError(f"output must have the shape of a1 {x1.shape}; got {out.shape}")
        diff = x1 - x2
        far = np.abs(diff) > t
        lam = np.where(far, (out - x2) / np.where(far, diff, 1.0), lam)
    return TheoremCheck(
        jerk_limit=J, dt=T, beta=b, tol=t,
        step=np.abs(np.diff(out, axis=-1)),
        step_ddpg=np.abs(np.diff(x1, axis=-1)),
        step_cacc=np.abs(np.diff(x2, axis=-1)),
        gap_prev=np.abs(x1[..., :-1] - x2[..., :-1]),
        weight_change=np.abs(np.diff(lam, axis=-1)),
        switch=np.asarray(alpha[..., 1:]),
        prev_switch=np.asarray(alpha[..., :-1]),
    )


def tight_example(jerk_limit: float, *, gap: float, case: Case = "switch", beta: float = BETA,
                  dt: float = DT) -> tuple[Array, Array, BoolArray]:
    """Two frames satisfying P1 and P2 (with equality) where |a_k − a_{k−1}| attains the bound.

    With Δ = a1_0 − a2_0 = ``gap`` and both candidates moving by J T in the direction of
    (λ_1 − λ_0) Δ, the step is J T + |λ_1 − λ_0| |Δ| exactly.  The strategy starts on CACC
    (``initial=False`` in :func:`check_theorem`).

    Parameters
    ----------
    jerk_limit : float
        J, m/s³.
    gap : float
        Δ = a1_0 − a2_0, m/s² (the amount by which P3 fails).
    case : {"switch", "after-switch", "double-switch"}
        A switch at frame 1 (|Δλ| = 1 − β); a switch at frame 0 and none at frame 1, the frame
        after a soft switch (|Δλ| = β); switches at both (|Δλ| = |1 − 2β|).
    beta, dt : float
        β and T.

    Returns
    -------
    (a1, a2, use_ddpg) : arrays of length 2

    Examples
    --------
    >>> a1, a2, c = tight_example(5.0, gap=0.4, case="after-switch")
    >>> chk = check_theorem(a1, a2, c, jerk_limit=5.0)
    >>> round(float(chk.step[0]), 9), round(float(chk.bound[0]), 9)
    (1.2, 1.2)
    """
    L = check_jerk_limit(jerk_limit) * positive("dt", dt, unit=" s")
    b = check_beta(beta)
    g = float(gap)
    if not math.isfinite(g):
        raise StringStabError(f"gap must be finite; got {gap!r}")
    choices = {"switch": [False, True], "after-switch": [True, True], "double-switch": [True, False]}
    if case not in choices:
        raise StringStabError(f"case must be one of {sorted(choices)}; got {case!r}")
    c = np.array(choices[case])
    lam, _ = switch_weights(c, beta=b)
    s = math.copysign(1.0, (lam[1] - lam[0]) * g) if g else 1.0
    a1 = np.array([g, g + s * L])
    a2 = np.array([0.0, s * L])
    return a1, a2, c


@dataclass(frozen=True)
class LatticeSearch:
    """Every 2-frame sequence on a lattice obeying P1 and P2, checked (:func:`lattice_search`).

    Attributes
    ----------
    q : int
        Lattice points per J T.
    a1, a2 : array (M, 2)
        The candidates of each sequence, in units of J T.
    use_ddpg : bool array (M, 2)
        The eq-12 choices.
    initial : bool array (M,)
        The choice before frame 0.
    check : TheoremCheck
        The theorem evaluated on every sequence (J T = 1).
    """

    q: int
    a1: Array
    a2: Array
    use_ddpg: BoolArray
    initial: BoolArray
    check: TheoremCheck

    @property
    def smallest_gap(self) -> float:
        """The smallest |a1_0 − a2_0| (in J T) of a counterexample (inf if there is none)."""
        cex = self.check.counterexamples[:, 0]
        return float(self.check.gap_prev[cex, 0].min()) if cex.any() else math.inf

    @property
    def largest_step_at_smallest_gap(self) -> float:
        """The largest |a_1 − a_0| (in J T) among the counterexamples with the smallest gap."""
        chk = self.check
        at = chk.counterexamples[:, 0] & np.isclose(chk.gap_prev[:, 0], self.smallest_gap)
        return float(chk.step[at, 0].max()) if at.any() else math.nan


def lattice_search(q: int, *, beta: float = BETA) -> LatticeSearch:
    """Exhaustive counterexample search without P3, on the lattice J T / q (J T = 1).

    Enumerates every 2-frame sequence with start values a1_0, a2_0 ∈ [−J T, J T] and steps
    in [−J T, J T] on the lattice (so P1 and P2 hold), every choice at both frames and before
    them, and checks the theorem.  The proposition of ``docs/hcfs.md`` predicts the smallest
    counterexample gap to be one lattice unit, 1/q, with a step of 1 + max|Δλ|/q at that gap.
    The number of sequences is 8 (2q + 1)⁴: keep q ≤ 12 or so (3·10⁶ sequences).

    Parameters
    ----------
    q : int
        Lattice points per J T (≥ 1).
    beta : float
        β of eqs 13-14.

    Returns
    -------
    LatticeSearch
        The sequences (in units of J T) and the theorem checked on each
        (:func:`check_theorem` with J = 1, T = 1).

    Raises
    ------
    StringStabError
        If q < 1 or β is not in [0, 1].

    Examples
    --------
    >>> s = lattice_search(4)
    >>> s.smallest_gap, s.largest_step_at_smallest_gap, int(s.check.violations.sum())
    (0.25, 1.125, 0)
    """
    n = int(q)
    if n < 1:
        raise StringStabError(f"q must be an integer >= 1; got {q!r}")
    vals = np.arange(-n, n + 1) / n
    g = np.array(np.meshgrid(vals, vals, vals, vals, [0, 1], [0, 1], [0, 1],
                             indexing="ij")).reshape(7, -1)
    a1 = np.stack([g[0], g[0] + g[2]], axis=-1)
    a2 = np.stack([g[1], g[1] + g[3]], axis=-1)
    use = np.stack([g[5], g[6]], axis=-1).astype(bool)
    initial = g[4].astype(bool)
    chk = check_theorem(a1, a2, use, jerk_limit=1.0, dt=1.0, beta=beta, initial=initial)
    return LatticeSearch(n, a1, a2, use, initial, chk)
