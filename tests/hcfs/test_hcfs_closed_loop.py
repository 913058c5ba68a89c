"""A small closed-loop verification of the jerk theorem, the §IV kinematics, the report and figures."""

import json

import matplotlib.pyplot as plt
import numpy as np
import pytest

from stringstab.errors import StringStabError
from stringstab.hcfs import constants as C
from stringstab.hcfs.plots import plot_figure, plot_jerk, plot_speed, plot_switching
from stringstab.hcfs.policy import LeaderSpeedMatcher
from stringstab.hcfs.report import write_report
from stringstab.hcfs.simulate import simulate_hcfs
from stringstab.hcfs.verify import verify
from stringstab.traffic.leaders import leader_by_name
from stringstab.traffic.synthetic import stop_and_go

JS = (2.5, 5.0)


@pytest.fixture(scope="module")
def ver():
    leaders = [leader_by_name("us06", dt=C.DT, duration=80), stop_and_go(waves=1, dt=C.DT)]
    return verify(leaders, LeaderSpeedMatcher(), jerk_limits=JS, n_followers=4)


def _result(ver, leader, mode, J):
    (x,) = [r for r in ver.results if r["leader"] == leader and r["mode"] == mode
            and r["jerk_limit"] == J]
    return x["totals"]


def test_theorem_holds_and_fails_without_p3(ver):
    """No frame falsifies a guarantee; HCFS by eqs 12-14 breaks J where P3 fails; the variant never."""
    assert ver.ok and not ver.violations
    for J in JS:
        for leader in ("us06", "stop-and-go"):
            paper = _result(ver, leader, "paper", J)
            safe = _result(ver, leader, "safe", J)
            # P1, P2 hold everywhere (rate limiters), P3 almost nowhere
            assert paper["P1_fails"] == paper["P2_fails"] == 0
            assert paper["P3_fails"] > 0.8 * paper["frames"]
            assert paper["violations"] == paper["bound_violations"] == 0
            assert paper["max_step_over_bound"] <= 1.0 + 1e-9
            assert safe["conclusion_fails"] == 0 and safe["max_jerk"] <= J * (1 + 1e-9)
    us06 = _result(ver, "us06", "paper", 2.5)
    assert us06["conclusion_fails"] > 0 and us06["max_jerk"] > 2 * 2.5
    assert len(ver.counterexamples) == sum(
        r["totals"]["counterexamples"] for r in ver.results if r["mode"] == "paper")
    sm = ver.smallest_counterexample
    assert sm is not None and sm.gap_prev == min(f.gap_prev for f in ver.counterexamples)
    assert all(f.step <= f.bound + 2e-9 and f.step > f.step_limit for f in ver.counterexamples)


def test_single_controller_modes_never_blend(ver):
    run = ver.runs[0]
    for i, cfg in enumerate(run.configs):
        if cfg.mode == "cacc":
            assert (run.weight[i] == 0).all() and np.array_equal(run.output[i], run.a_cacc[i])
        if cfg.mode == "policy":
            assert (run.weight[i] == 1).all() and np.array_equal(run.output[i], run.a_ddpg[i])


def test_checker_recomputes_the_applied_paper_output(ver):
    """The check of the 'paper' mode recomputes eq 13 from the applied choices: same numbers."""
    run = ver.runs[0]
    i = run.index("paper", 2.5)
    chk = run.check(i)
    out = np.concatenate([np.zeros((run.n_followers, 1)), run.output[i]], axis=-1)
    np.testing.assert_array_equal(chk.step, np.abs(np.diff(out, axis=-1)))


def test_kinematics_of_section_iv():
    """v_{k+1} = v_k + a_k T and x_{k+1} = x_k + v_k T + a_k T²/2 where no speed bound binds."""
    lead = leader_by_name("us06", dt=C.DT, duration=40)
    run = simulate_hcfs(lead, LeaderSpeedMatcher(), n_followers=3, configs=[("paper", 5.0)])
    x, v, a = run.position[0, 1:], run.speed[0, 1:], run.output[0]
    free = (v[:, 1:] > 0) & (v[:, 1:] < C.SPEED_MAX)
    T = C.DT
    np.testing.assert_allclose((v[:, :-1] + a[:, :-1] * T)[free], v[:, 1:][free], rtol=0, atol=1e-12)
    np.testing.assert_allclose((x[:, :-1] + v[:, :-1] * T + 0.5 * a[:, :-1] * T * T)[free],
                               x[:, 1:][free], rtol=0, atol=1e-9)
    np.testing.assert_allclose(run.speed[0, 0], lead.speed, rtol=0, atol=0)


def test_bad_inputs():
    lead = stop_and_go(waves=1, dt=C.DT)
    with pytest.raises(StringStabError, match="jerk limit J must be a finite number > 0"):
        verify([lead], LeaderSpeedMatcher(), jerk_limits=[0.0], n_followers=2)
    with pytest.raises(StringStabError, match="mode must be one of"):
        simulate_hcfs(lead, LeaderSpeedMatcher(), n_followers=2, configs=[("ddpg", 1.0)])
    with pytest.raises(StringStabError, match="at most one frame"):
        simulate_hcfs(lead, LeaderSpeedMatcher(), n_followers=2, configs=[("paper", 1.0)], delay=1.0)
    with pytest.raises(StringStabError, match="n_followers must be an integer"):
        simulate_hcfs(lead, LeaderSpeedMatcher(), n_followers=0, configs=[("paper", 1.0)])


def test_report(ver, tmp_path):
    files = write_report(ver, tmp_path, figures=False, command="stringstab hcfs verify ...")
    assert sorted(p.name for p in tmp_path.iterdir() if not p.name.startswith(".")) == [
        "report.html", "report.json", "report.md"]
    assert sorted(files.values()) == ["report.html", "report.json", "report.md"]
    doc = json.loads((tmp_path / "report.json").read_text())
    assert doc["ok"] is True and doc["exit_code"] == 0
    assert doc["setup"]["policy_is_stand_in"] is True
    assert doc["counterexamples"]["count"] == len(ver.counterexamples)
    assert doc["counterexamples"]["smallest"]["gap_prev"] == ver.smallest_counterexample.gap_prev
    md = (tmp_path / "report.md").read_text()
    assert "**stand-in**, not a DDPG" in md and "| smallest → " in md
    # the smallest counterexample is listed once (it used to be repeated among the largest)
    row = next(line for line in md.splitlines() if line.startswith("| smallest → "))
    assert md.count(row.removeprefix("| smallest → ")) == 1
    assert "DDPG alone" not in md  # the stand-in is never presented as a DDPG


def test_report_figures(tmp_path):
    small = verify([stop_and_go(waves=1, dt=C.DT)], LeaderSpeedMatcher(), jerk_limits=[5.0],
                   n_followers=2)
    write_report(small, tmp_path, figures=True)
    pngs = sorted(p.name for p in tmp_path.glob("*.png"))
    assert pngs == ["jerk_1-stop-and-go_J5.png", "speed_1-stop-and-go_J5.png",
                    "switching_1-stop-and-go_J5.png"]
    assert all((tmp_path / n).stat().st_size > 10_000 for n in pngs)
    md = (tmp_path / "report.md").read_text()
    assert all(f"]({n})" in md for n in pngs)


def test_plots_return_what_they_drew(ver):
    run = ver.runs[1]
    i = run.index("paper", 5.0)
    fig, axes = plt.subplots(3)
    try:
        lead, lc = plot_speed(run, i, ax=axes[0])
        assert lead.get_ydata().shape == run.t.shape and len(lc.get_segments()) == 4
        arts = plot_jerk(run, i, ax=axes[1])
        # the followers, ±J, and ±2a_max/T only when the jerk comes near it (not here)
        assert len(arts) == 3 and arts[1].get_ydata()[0] == pytest.approx(5.0)
        assert "frames above J" in axes[1].get_title(loc="right")  # the count, in words
        img = plot_switching(run, i, ax=axes[2])
        assert img.get_array().shape == (4, run.t.size)
        assert "stand-in policy" in axes[0].get_title() or "HCFS" in axes[0].get_title()
    finally:
        plt.close(fig)
    fig2, axes2 = plot_figure(run, 5.0, "jerk")
    try:  # a panel per follower (rows) and mode (columns), not the followers on top of each other
        assert len(axes2) == 4 * run.n_followers
        assert [ax.get_title(loc="left").split("\n")[0] for ax in axes2][:2] == [
            "CACC alone", "stand-in policy alone"]
        assert all(len(ax.get_lines()) == 3 for ax in axes2)  # one follower, +J, −J
        assert "2a_max/T = 30 m/s³, beyond every panel's scale" in fig2.get_suptitle()
    finally:
        plt.close(fig2)
    with pytest.raises(StringStabError, match="no configuration"):
        plot_figure(run, 7.0, "speed")
