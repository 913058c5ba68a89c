"""The HCFS paper's leaders on the bundled data (UDDS at half speed) and the Table IV-style comparison."""

import numpy as np
import pytest

from stringstab.errors import StringStabError
from stringstab.hcfs import constants as C
from stringstab.hcfs.compare import COLUMNS, compare_controllers, comparison_markdown
from stringstab.hcfs.env import default_training_leaders
from stringstab.hcfs.leaders import (
    CASES,
    TRAINING_START,
    case_leader,
    half_speed,
    hcfs_leader,
    paper_cases,
    training_leader,
)
from stringstab.hcfs.policy import LeaderSpeedMatcher
from stringstab.hcfs.simulate import simulate_hcfs
from stringstab.traffic.cycles import cycle
from stringstab.traffic.synthetic import stop_and_go


def _kinematics_residual(tr):
    """x_{k+1} − (x_k + v_k T + ½ a_k T²) and v_{k+1} − (v_k + a_k T): the paper's §IV leader."""
    T = tr.dt
    x, v, a = tr.position, tr.speed, tr.accel
    return (x[1:] - (x[:-1] + v[:-1] * T + 0.5 * a[:-1] * T * T), v[1:] - (v[:-1] + a[:-1] * T))


def test_half_speed_keeps_the_leader_exact():
    udds = cycle("udds", dt=C.DT)
    half = half_speed(udds)
    np.testing.assert_allclose(half.speed, udds.speed / 2, rtol=0, atol=0)
    for r in _kinematics_residual(half):
        np.testing.assert_allclose(r, 0.0, rtol=0, atol=1e-9)
    with pytest.raises(StringStabError, match="speed factor must be a finite number > 0; got 0"):
        half_speed(udds, factor=0)


def test_training_leader_is_udds_at_half_speed_from_600_s():
    udds = cycle("udds", dt=C.DT)
    tr = training_leader()
    k0 = round(TRAINING_START / C.DT)
    assert tr.duration == pytest.approx(udds.duration - TRAINING_START, abs=1e-9)
    np.testing.assert_allclose(tr.speed, udds.speed[k0:] / 2, rtol=0, atol=0)
    assert default_training_leaders()[0].name == tr.name == "udds/2 600-1369 s"


def test_cases_are_held_out_and_chosen_by_the_documented_rule():
    """Three 20 s windows of [0, 600) s, the largest Σ|Δv| among starts on a 20 s grid."""
    v = half_speed(cycle("udds", dt=C.DT)).speed
    n = round(20 / C.DT)
    variation = {s: np.abs(np.diff(v[round(s / C.DT):round(s / C.DT) + n + 1])).sum()
                 for s in range(0, 600 - 20 + 1, 20)}
    top3 = sorted(variation, key=variation.get, reverse=True)[:3]
    assert sorted(top3) == sorted(start for start, _, _ in CASES.values())
    for name, (start, stop, n_f) in CASES.items():
        tr, n_followers = case_leader(name)
        assert stop <= TRAINING_START and tr.duration == pytest.approx(stop - start, abs=1e-9)
        np.testing.assert_allclose(tr.speed, v[round(start / C.DT):round(stop / C.DT) + 1], rtol=0, atol=0)
        assert n_followers == n_f
    # case 1 starts from standstill and speeds up, like the printed case 1; N = 8, 6, 4 as in §IV
    c1, _ = case_leader("hcfs-case1")
    assert c1.speed[0] == 0.0 and c1.speed[-1] > 7.0
    assert [n for _, n in paper_cases()] == [8, 6, 4]


def test_hcfs_leader_names_and_fallback():
    assert hcfs_leader("hcfs-train").name == training_leader().name
    assert hcfs_leader("HCFS-Case2", duration=5.0).duration == pytest.approx(5.0)
    np.testing.assert_allclose(hcfs_leader("stop-and-go").speed, stop_and_go(dt=C.DT).speed, rtol=0, atol=0)
    with pytest.raises(StringStabError, match="unknown leader 'moon'"):
        hcfs_leader("moon")
    with pytest.raises(StringStabError, match="duration must be > 0 s"):
        hcfs_leader("hcfs-case1", duration=-1.0)
    with pytest.raises(StringStabError, match="unknown HCFS test case 'hcfs-case9'"):
        case_leader("hcfs-case9")


def test_comparison_sums_decompose_as_eqs_4_to_6():
    """Σr = −(ω1/v_max) Σ|e_v| − (ω2 T/(2 a_max)) Σ|jerk| (the relation the ω fit uses), with the
    sums taken by the verification and the rewards earned in the simulator."""
    cases = paper_cases()[2:]
    rows = compare_controllers(cases, LeaderSpeedMatcher(), name="stand-in")
    assert [r["controller"] for r in rows] == ["CACC", "stand-in", "HCFS"]
    lead, n = cases[0]
    run = simulate_hcfs(lead, LeaderSpeedMatcher(), n_followers=n,
                        configs=[("cacc", C.PAPER_JERK_LIMIT), ("policy", C.PAPER_JERK_LIMIT),
                                 ("paper", C.PAPER_JERK_LIMIT)])
    for i, r in enumerate(rows):
        assert set(COLUMNS) <= set(r) and r["n_followers"] == n
        # the reward is earned for frames 0..K-2; the sums also count the last frame's jerk
        last_jerk = np.abs(run.output[i, :, -1] - run.output[i, :, -2]).sum() / C.DT
        predicted = (-C.OMEGA_1 / C.SPEED_MAX * r["sum_abs_speed_error"]
                     - C.OMEGA_2 * C.DT / (2 * C.ACCEL_MAX) * (r["sum_abs_jerk"] - last_jerk))
        assert r["sum_reward"] == pytest.approx(predicted, rel=1e-9, abs=1e-9)
    md = comparison_markdown(rows)
    assert md.count("\n") == 2 + len(rows) and "| HCFS |" in md


def test_comparison_with_other_policies():
    rows = compare_controllers(paper_cases()[2:], LeaderSpeedMatcher(), name="a",
                               others={"b": LeaderSpeedMatcher(kappa=1.0)})
    assert [r["controller"] for r in rows] == ["CACC", "a", "HCFS", "b", "HCFS (b)"]
    alone = compare_controllers(paper_cases()[2:], LeaderSpeedMatcher(kappa=1.0), name="b")
    assert rows[3] == alone[1] and rows[4] == {**alone[2], "controller": "HCFS (b)"}
    assert rows[1]["sum_abs_speed_error"] != rows[3]["sum_abs_speed_error"]
