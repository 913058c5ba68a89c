"""The Monte-Carlo radio study (issue 26 item 4): ``stringstab.traffic.radio_study`` and ``stringstab radio``.

Independent truths: a direct ``simulate`` run with its trajectories recorded (the study reads
only the run's energy summaries); the sampled-data certificate (a certified loop with a message
every step and no loss cannot amplify a signal started at rest: the finite-horizon ℓ2 gain of a
causal stable LTI system is at most its H∞ norm); the Student-t interval's coverage on normal
samples of known mean; a closed-form crossing.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from stringstab.cli import main
from stringstab.traffic import LinearController, Radio, SensorNoise, simulate, sinusoid
from stringstab.traffic.radio_study import first_exceedance, run_radio_study, t_interval

K_CERT = (1.2, 0.5, 0.6)  # certified, continuous and sampled at H = 0.01 s (asserted below)


def _leader(duration=30.0):
    return sinusoid(omega=2.0, amplitude=0.5, duration=duration, dt=0.01)


def test_no_loss_equals_a_direct_simulate_run():
    leader = _leader()
    st = run_radio_study([K_CERT], leader, n_followers=4, message_period=0.1, losses=[0.0],
                         bursts=[1.0], seeds=2)
    res = simulate(leader, LinearController(*K_CERT), 4, radio=Radio(message_period=0.1))
    a = res.accel  # (N + 1, T), recorded: the study never sees it
    e = np.sum(a**2, axis=-1)
    m_p = np.sqrt(e[1:] / e[:-1])
    for r in range(2):  # no loss, no noise: both replicates are this run
        np.testing.assert_allclose(st.m_p[0, 0, 0, r], m_p, rtol=1e-9, atol=0)
        np.testing.assert_allclose(st.gain_first[0, 0, 0, r], np.sqrt(e[-1] / e[1]), rtol=1e-9)
        np.testing.assert_allclose(st.gain_leader[0, 0, 0, r], np.sqrt(e[-1] / e[0]), rtol=1e-9)
    assert st.loss_share[0, 0, 0].tolist() == [0.0, 0.0]
    assert st.amplification[0, 0, 0, 0] == pytest.approx(m_p.max(), rel=1e-9)


def test_certified_loop_without_loss_does_not_amplify():
    # messages every step (P = H): the loop the sampled certificate decides
    st = run_radio_study([K_CERT], _leader(60.0), n_followers=6, message_period=0.01,
                         losses=[0.0], bursts=[1.0], seeds=2)
    cert = st.certificates[0]
    assert cert["sampled"]["verdict"] == "certified" and cert["continuous"]["verdict"] == "certified"
    assert cert["multirate"] is None
    amp = st.amplification[0, 0, 0]
    assert np.all(amp <= 1.0 + 1e-6), amp
    assert np.all(st.gain_first[0, 0, 0] <= 1.0 + 1e-6)
    assert st.covered(0.0) == "sampled certificate (messages every step)"
    assert st.covered(0.1).startswith("not covered: random loss")


def test_uncertified_gains_amplify_at_the_peak():
    # the van Arem CACC gains, not certified (|Γ(j2)| ≈ 1.14): a sinusoid at ω = 2 grows
    st = run_radio_study([(0.1, 0.58, 1.0)], _leader(60.0), n_followers=4, message_period=0.01,
                         losses=[0.0], bursts=[1.0], seeds=2)
    assert st.certificates[0]["sampled"]["verdict"] == "not_certified"
    assert st.amplification[0, 0, 0, 0] > 1.05


def test_t_interval_closed_form_and_coverage():
    m, lo, hi = t_interval([1.0, 2.0, 3.0, 4.0])
    # t_{0.975, 3} = 3.182446305284263 (tables); s = sqrt(5/3)
    half = 3.182446305284263 * np.sqrt(5 / 3) / 2
    np.testing.assert_allclose([m, lo, hi], [2.5, 2.5 - half, 2.5 + half], rtol=1e-12)
    assert all(np.isnan(t_interval([1.0])[1:]))
    rng = np.random.default_rng(7)
    x = rng.normal(3.0, 2.0, size=(4000, 6))
    cover = np.mean([lo <= 3.0 <= hi for _, lo, hi in map(t_interval, x)])
    assert 0.935 <= cover <= 0.965  # 95 % nominal; binomial sd 0.0034 over 4000 trials


def test_first_exceedance_interpolates():
    p = [0.0, 0.1, 0.2, 0.3]
    e = first_exceedance(p, [0.9, 0.95, 1.05, 1.2], [0.85, 0.9, 0.95, 1.15], [0.95, 1.0, 1.15, 1.25])
    assert e["loss"] == pytest.approx(0.15, abs=1e-12)
    assert e["loss_lo"] == pytest.approx(0.1, abs=1e-12)  # upper bound: 1.0 is not above 1
    assert e["loss_hi"] == pytest.approx(0.2 + 0.1 * 0.05 / 0.2, abs=1e-12)
    assert first_exceedance(p, [0.9] * 4, [0.8] * 4, [0.99] * 4) == {
        "loss": None, "loss_lo": None, "loss_hi": None}
    assert first_exceedance(p, [1.1] * 4, [1.05] * 4, [1.2] * 4)["loss"] == 0.0


def _noisy(seeds, seed=0):
    return run_radio_study([(0.45, 0.25, 0.9)], _leader(20.0), n_followers=3, message_period=0.1,
                           losses=[0.0, 0.2], bursts=[1.0, 5.0], seeds=seeds, seed=seed,
                           sensors=SensorNoise(speed=0.05))


def test_intervals_contain_the_mean_and_shrink_with_more_seeds():
    small, large = _noisy(4), _noisy(32)
    s, big = small.summary(), large.summary()
    # mean inside its interval: holds by construction of mean ± half-width (not evidence)
    assert np.all((s[..., 1] <= s[..., 0]) & (s[..., 0] <= s[..., 2]))
    w_small, w_large = s[..., 2] - s[..., 1], big[..., 2] - big[..., 1]
    assert np.all(w_small > 0)
    # ~ t_{.975,3}/t_{.975,31} · √(32/4) ≈ 4.4 times narrower; asserted: at least twice
    assert np.all(w_large < 0.5 * w_small), (w_small, w_large)


def test_same_seed_same_table_other_seed_other_table():
    a, b, c = _noisy(3), _noisy(3), _noisy(3, seed=1)
    assert a.rows() == b.rows()
    np.testing.assert_array_equal(a.m_p, b.m_p)
    assert not np.array_equal(a.m_p, c.m_p)
    assert a.loss_share[0, 0, 1].mean() > 0.05  # p = 0.2: messages were lost


def test_loss_shares_are_the_rates_asked():
    st = run_radio_study([K_CERT], _leader(60.0), n_followers=3, message_period=0.1,
                         losses=[0.0, 0.3], bursts=[1.0, 5.0], seeds=8)
    # 8 × 3 links × 600 messages: binomial sd ≈ 0.0108 independent; bursts of 5 ≈ 3× wider
    assert np.all(st.loss_share[0, :, 0] == 0.0)
    assert abs(st.loss_share[0, 0, 1].mean() - 0.3) < 0.03
    assert abs(st.loss_share[0, 1, 1].mean() - 0.3) < 0.09


TINY = ["--leader", "sinusoid:omega=2,amplitude=0.5", "--duration", "15", "--hold", "0",
        "--followers", "3", "--seeds", "2", "--loss", "0,0.2", "--burst", "1,3", "--no-progress"]


def test_cli_writes_the_study(tmp_path, capsys):
    out = tmp_path / "study"
    assert main(["radio", *TINY, "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "multi-rate certificate: not on this branch" in text
    names = {p.name for p in out.iterdir() if not p.name.startswith(".")}
    assert {"table.csv", "table.md", "study.json", "amplification.png", "links.png", "report.md",
            "report.html"} <= names
    doc = json.loads((out / "study.json").read_text(encoding="utf-8"))
    assert len(doc["rows"]) == 2 * 2 * 2  # two default triples × bursts × losses
    assert "covered by no certificate" in doc["not_covered"]
    csv_lines = (out / "table.csv").read_text(encoding="utf-8").splitlines()
    assert len(csv_lines) == 1 + 8 and csv_lines[0].startswith("k_x,k_v,k_a,loss,burst,seeds,max_m_p")


@pytest.mark.parametrize("extra, match", [
    (["--loss", "0,1.5"], "--loss must be a number in [0, 1]; got '1.5'"),
    (["--loss", "0.2,0.1"], "--loss must be strictly increasing"),
    (["--burst", "0.5"], "--burst must be a finite number >= 1"),
    (["--noise-gap", "-1"], "--noise-gap must be a finite number >= 0"),
    (["--message-period", "0.015"], "--message-period"),
    (["--seeds", "1"], "--seeds"),
    (["--loss", "0,nan"], "--loss must be a number in [0, 1]"),
    # simulate's own step check (cli.simulate.check_step): a step longer than τ or δ
    (["--dt", "0.2", "--tau", "0.1", "--delta", "0.3"],
     "--dt 0.2 s is longer than the actuator lag tau = 0.1 s: "),
    (["--dt", "0.05", "--tau", "0.1", "--delta", "0.02"], "longer than the delay delta = 0.02 s"),
    (["--dt", "1e-300"], "--dt = 1e-300 s is far outside"),
    (["--length", "1e300"], "--length = 1e+300 m is far outside"),
])
def test_cli_bad_input_is_one_line_exit_2(tmp_path, capsys, extra, match):
    out = tmp_path / "o"
    args = list(TINY)
    for flag in ("--loss", "--burst", "--seeds"):
        if flag in extra and flag in args:
            i = args.index(flag)
            del args[i:i + 2]
    assert main(["radio", *args, *extra, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and match in err[0], err
    assert not out.exists()
