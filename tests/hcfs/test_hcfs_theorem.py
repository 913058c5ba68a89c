"""The HCFS jerk theorem: property tests in exact arithmetic, the bound, its tightness, a counterexample search."""

from fractions import Fraction
from itertools import product

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, find, given, settings
from hypothesis import strategies as st

from stringstab.errors import StringStabError
from stringstab.hcfs.switching import limit_step, switch_weights
from stringstab.hcfs.theorem import (
    DEFAULT_TOL,
    check_theorem,
    jerk_bound,
    lattice_search,
    tight_example,
    weight_change,
)

DT = 0.2


def exact_outputs(a1, a2, use_ddpg, beta, initial=False):
    """The eq-13/14 output in exact rational arithmetic (independent of the float code)."""
    b = Fraction(beta)
    prev = initial
    lam, out = [], []
    for x1, x2, c in zip(a1, a2, use_ddpg):
        bk = b if c != prev else Fraction(0)
        w = 1 - bk if c else bk
        lam.append(w)
        out.append(w * Fraction(x1) + (1 - w) * Fraction(x2))
        prev = c
    return lam, out


@st.composite
def sequences(draw, *, sync=True, max_frames=12):
    """Candidates satisfying P1 and P2 by construction; at 'sync' frames a2 jumps onto a1 when
    P2 allows it, so that P3 holds at the next transition."""
    J = draw(st.floats(0.1, 40.0))
    L = J * DT
    K = draw(st.integers(2, max_frames))
    a1 = [draw(st.floats(-3.0, 3.0))]
    a2 = [a1[0] if draw(st.booleans()) else draw(st.floats(-3.0, 3.0))]
    for _ in range(K - 1):
        a1.append(a1[-1] + draw(st.floats(-1.0, 1.0)) * L)
        nxt = a2[-1] + draw(st.floats(-1.0, 1.0)) * L
        if sync and draw(st.booleans()) and abs(Fraction(a1[-1]) - Fraction(a2[-1])) <= Fraction(L):
            nxt = a1[-1]
        a2.append(nxt)
    use = draw(st.lists(st.booleans(), min_size=K, max_size=K))
    beta = draw(st.sampled_from([0.0, 0.25, 0.5, 0.75, 1.0]) | st.floats(0.0, 1.0))
    return J, np.array(a1), np.array(a2), np.array(use), beta


def exact_premises(J, a1, a2, k):
    L = Fraction(J) * Fraction(DT)
    p1 = abs(Fraction(a1[k]) - Fraction(a1[k - 1])) <= L
    p2 = abs(Fraction(a2[k]) - Fraction(a2[k - 1])) <= L
    p3 = Fraction(a1[k - 1]) == Fraction(a2[k - 1])
    return p1, p2, p3, L


@given(sequences())
@settings(suppress_health_check=[HealthCheck.too_slow])
def test_conclusion_holds_under_all_premises(seq):
    """(a) P1 ∧ P2 ∧ P3 ⇒ |a_k − a_{k−1}| ≤ J T, exactly, at every frame; the checker agrees."""
    J, a1, a2, use, beta = seq
    _, out = exact_outputs(a1, a2, use, beta)
    chk = check_theorem(a1, a2, use, jerk_limit=J, dt=DT, beta=beta)
    held = 0
    for k in range(1, len(a1)):
        p1, p2, p3, L = exact_premises(J, a1, a2, k)
        if p1 and p2 and p3:
            held += 1
            assert abs(out[k] - out[k - 1]) <= L
            assert chk.premises[k - 1] and chk.conclusion[k - 1]
    assert not chk.violations.any()
    assume(held > 0)


@given(sequences(sync=False))
def test_bound_holds_without_p3(seq):
    """Under P1 ∧ P2 alone, |a_k − a_{k−1}| ≤ J T + |λ_k − λ_{k−1}| |a1_{k−1} − a2_{k−1}|, exactly."""
    J, a1, a2, use, beta = seq
    lam, out = exact_outputs(a1, a2, use, beta)
    chk = check_theorem(a1, a2, use, jerk_limit=J, dt=DT, beta=beta)
    alpha = switch_weights(use, beta=beta)[1]
    for k in range(1, len(a1)):
        p1, p2, _, L = exact_premises(J, a1, a2, k)
        if not (p1 and p2):
            continue
        gap = abs(Fraction(a1[k - 1]) - Fraction(a2[k - 1]))
        dlam = abs(lam[k] - lam[k - 1])
        assert abs(out[k] - out[k - 1]) <= L + dlam * gap
        # the closed form of |Δλ| from the switch states (the table in weight_change)
        assert float(dlam) == pytest.approx(
            float(weight_change(alpha[k - 1], alpha[k], beta)), abs=1e-15)
        assert chk.within_bound[k - 1]
    assert not chk.bound_violations.any()


@given(sequences(sync=False))
def test_safe_variant_needs_only_p1_p2(seq):
    """The jerk-safe variant: |a_k − a_{k−1}| ≤ J T at every frame, output in [min, max](a1_k, a2_k)."""
    J, a1, a2, use, beta = seq
    lam, _ = switch_weights(use, beta=beta)
    target = lam * a1 + (1 - lam) * a2
    out = np.empty_like(target)
    out[0] = prev = target[0]
    for k in range(1, len(a1)):
        out[k] = prev = float(limit_step(target[k], prev, J * DT))
    lo, hi = np.minimum(a1, a2), np.maximum(a1, a2)
    assert ((out >= lo - 1e-12) & (out <= hi + 1e-12)).all()
    chk = check_theorem(a1, a2, use, jerk_limit=J, dt=DT, beta=beta, output=out)
    ok = chk.rate_ddpg & chk.rate_cacc
    assert chk.conclusion[ok].all()
    assert not chk.bound_violations.any()


@pytest.mark.parametrize("case", ["switch", "after-switch", "double-switch"])
@pytest.mark.parametrize("beta", [0.0, 0.3, 0.5, 0.8, 1.0])
@pytest.mark.parametrize("gap", [-1.7, -1e-6, 1e-6, 0.4, 2.5])
def test_bound_is_attained(case, beta, gap):
    """tight_example: P1, P2 hold with equality and the step equals the bound."""
    J = 5.0
    a1, a2, use = tight_example(J, gap=gap, case=case, beta=beta, dt=DT)
    chk = check_theorem(a1, a2, use, jerk_limit=J, dt=DT, beta=beta)
    expected = {"switch": 1 - beta, "after-switch": beta, "double-switch": abs(1 - 2 * beta)}[case]
    assert chk.rate_ddpg.all() and chk.rate_cacc.all() and not chk.equal_prev.any()
    np.testing.assert_allclose(chk.step, J * DT + expected * abs(gap), rtol=0, atol=1e-12)
    np.testing.assert_allclose(chk.bound, chk.step, rtol=0, atol=1e-12)
    assert bool(chk.conclusion[0]) == (expected * abs(gap) <= 2 * DEFAULT_TOL)


def test_weight_change_table_is_exhaustive():
    """|Δλ| from eqs 13-14 for every (c_{k−2}, c_{k−1}, c_k) equals the closed-form table."""
    for beta in (0.0, 0.2, 0.5, 0.9, 1.0):
        for c in product([False, True], repeat=3):
            lam, alpha = switch_weights(list(c[1:]), beta=beta, initial=c[0])
            assert abs(lam[1] - lam[0]) == pytest.approx(
                float(weight_change(alpha[0], alpha[1], beta)), abs=1e-15)
    assert float(jerk_bound(5.0, -0.4, True, False, beta=0.25, dt=DT)) == pytest.approx(1.1, abs=1e-15)


def test_exhaustive_lattice_search_finds_the_smallest_counterexample():
    """(b) Dropping P3: on the lattice of step J T / q the smallest |a1_{k−1} − a2_{k−1}| of a
    counterexample is one lattice unit, for every q — no ε > 0 relaxation of P3 saves C; at
    that gap the largest step is the bound J T (1 + max|Δλ|/q) = J T (1 + 1/(2q)) at β = 0.5."""
    for q in (2, 4, 8):
        s = lattice_search(q, beta=0.5)
        chk = s.check
        assert chk.counterexamples.any() and not chk.violations.any()
        assert not chk.bound_violations.any() and (chk.step <= chk.bound + 1e-12).all()
        assert chk.rate_ddpg.all() and chk.rate_cacc.all()
        assert s.smallest_gap == pytest.approx(1.0 / q, abs=1e-12)
        assert s.largest_step_at_smallest_gap == pytest.approx(1.0 + 0.5 / q, abs=1e-12)
        # independent recomputation of the outputs: C fails exactly where |a_1 − a_0| > J T
        lam, _ = switch_weights(s.use_ddpg, beta=0.5, initial=s.initial)
        out = lam * s.a1 + (1 - lam) * s.a2
        assert np.array_equal(np.abs(out[:, 1] - out[:, 0]) > 1 + 2 * DEFAULT_TOL,
                              ~chk.conclusion[:, 0])


SEARCH_J = 5.0


@st.composite
def short_sequences(draw):
    """Sequences of 2-6 frames on a lattice of J T / 16, with P1 and P2 by construction."""
    L = SEARCH_J * DT
    K = draw(st.integers(2, 6))
    a1 = [draw(st.integers(-48, 48)) * L / 16]
    a2 = [draw(st.integers(-48, 48)) * L / 16]
    for _ in range(K - 1):
        a1.append(a1[-1] + draw(st.integers(-16, 16)) * L / 16)
        a2.append(a2[-1] + draw(st.integers(-16, 16)) * L / 16)
    use = draw(st.lists(st.booleans(), min_size=K, max_size=K))
    return np.array(a1), np.array(a2), np.array(use)


def _check(seq, initial=False):
    a1, a2, use = seq
    return check_theorem(a1, a2, use, jerk_limit=SEARCH_J, dt=DT, beta=0.5, initial=initial)


def _violates(seq, gap_max=np.inf):
    chk = _check(seq)
    return bool((chk.counterexamples & (chk.gap_prev <= gap_max + 1e-12)).any())


def _localise(seq):
    """The first failing transition k−1 → k alone: frames k−1, k and the choice before them."""
    a1, a2, use = seq
    j = int(np.flatnonzero(_check(seq).counterexamples)[0]) + 1
    initial = bool(use[j - 2]) if j >= 2 else False
    return (a1[j - 1:j + 1], a2[j - 1:j + 1], use[j - 1:j + 1]), initial


def test_hypothesis_finds_counterexamples_without_p3():
    """(b) Hypothesis searches sequences satisfying P1 and P2 (not P3) for a failing conclusion.

    Smallest = fewest frames, then the smallest |a1_{k−1} − a2_{k−1}| at the failing frame.
    The theorem is local, so any counterexample reduces to its failing transition (2 frames).
    The lattice integers shrink towards 0 and a gap of 0 cannot fail, so the shrunk example
    has the smallest gap the lattice allows, one unit (J T / 16): a relaxation
    |a1_{k−1} − a2_{k−1}| ≤ ε of P3 fails for every ε ≥ one unit, and the exhaustive lattice test
    above shows the same at every resolution.
    """
    opts = settings(max_examples=3000, database=None, derandomize=True)
    L = SEARCH_J * DT
    found = find(short_sequences(), _violates, settings=opts)
    two, initial = _localise(found)
    chk = _check(two, initial)
    assert len(two[0]) == 2 and chk.counterexamples[0]
    assert chk.rate_ddpg.all() and chk.rate_cacc.all() and chk.within_bound.all()
    assert chk.gap_prev[0] == pytest.approx(L / 16, abs=1e-12)
    np.testing.assert_allclose(chk.step[0], L + chk.weight_change[0] * L / 16, rtol=0, atol=1e-12)
    print(f"smallest counterexample found: a1={two[0].tolist()}, a2={two[1].tolist()}, DDPG "
          f"chosen={two[2].tolist()} (before: {initial}), |a1-a2| at k-1 = {chk.gap_prev[0]:.4g}, "
          f"jerk {chk.step[0] / DT:.6g} > J={SEARCH_J}")


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"jerk_limit": 0.0}, "jerk limit J must be a finite number > 0"),
        ({"jerk_limit": float("nan")}, "jerk limit J must be a finite number > 0"),
        ({"jerk_limit": float("inf")}, "jerk limit J must be a finite number > 0"),
        ({"jerk_limit": 1.0, "beta": 1.5}, r"beta must be a number in \[0, 1\]"),
        ({"jerk_limit": 1.0, "beta": float("nan")}, r"beta must be a number in \[0, 1\]"),
    ],
)
def test_bad_parameters(kwargs, match):
    with pytest.raises(StringStabError, match=match):
        check_theorem([0.0, 1.0], [0.0, 1.0], [False, True], **kwargs)


def test_bad_sequences():
    with pytest.raises(StringStabError, match="one shape"):
        check_theorem([0.0, 1.0], [0.0, 1.0, 2.0], [False, True], jerk_limit=1.0)
    with pytest.raises(StringStabError, match="frame axis of length >= 2"):
        check_theorem([0.0], [0.0], [False], jerk_limit=1.0)
    with pytest.raises(StringStabError, match="must be finite"):
        check_theorem([0.0, np.nan], [0.0, 1.0], [False, True], jerk_limit=1.0)


def test_paper_proof_gap_frame_after_a_switch():
    """The proof treats 'no switch' frames as a_{k−1} = a1_{k−1}; after a soft switch the
    previous output is the blend, and the step exceeds J T by β |a1_{k−1} − a2_{k−1}|."""
    J, L = 5.0, 5.0 * DT
    a1 = np.array([0.0, 0.8, 0.8 + L])  # DDPG: moves by exactly L
    a2 = np.array([0.0, 0.0, 0.0])  # CACC: still
    use = np.array([False, True, True])  # switch at frame 1, none at frame 2
    chk = check_theorem(a1, a2, use, jerk_limit=J, dt=DT, beta=0.5)
    assert not chk.switch[1] and chk.prev_switch[1]
    np.testing.assert_allclose(chk.step[1], L + 0.5 * 0.8, rtol=0, atol=1e-12)
    assert not chk.conclusion[1] and chk.within_bound[1]
