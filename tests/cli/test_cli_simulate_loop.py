"""``stringstab simulate`` with --reaction-delay and the radio and sensor flags (issues 25, 26).

Neutral values change nothing in the files written; bad input is one line on stderr, exit 2,
nothing written; ``--from`` carries a fitted θ_r.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from stringstab.cli import main

BASE = ["--leader", "sinusoid:omega=2,amplitude=0.5", "--duration", "20", "--followers", "3",
        "--no-figures"]


def _run(tmp_path, name, *extra):
    out = tmp_path / name
    rc = main(["simulate", *BASE, *extra, "--out", str(out)])
    return rc, out


def _arrays(out):
    with np.load(out / "trajectories.npz") as z:
        return {k: z[k] for k in z.files}


def test_neutral_values_write_the_same_files(tmp_path, capsys):
    rc, a = _run(tmp_path, "a")
    assert rc == 0
    rc, b = _run(tmp_path, "b", "--reaction-delay", "0")
    assert rc == 0
    assert (a / "metrics.json").read_text(encoding="utf-8") == (b / "metrics.json").read_text(encoding="utf-8")
    rc, c = _run(tmp_path, "c", "--message-period", "0.1", "--loss", "0")  # one message per step
    assert rc == 0
    A, C = _arrays(a), _arrays(c)
    assert A.keys() == C.keys()
    for k in A:
        if k != "params":  # the run's params (JSON) name the radio
            np.testing.assert_array_equal(A[k], C[k])
    da = json.loads((a / "metrics.json").read_text(encoding="utf-8"))
    dc = json.loads((c / "metrics.json").read_text(encoding="utf-8"))
    assert dc["run"].pop("radio")["message_period"] == 0.1
    assert dc["certificate"].pop("scope")
    assert dc.pop("radio")["messages_lost"] == [0, 0, 0]
    assert dc == da
    capsys.readouterr()


def test_reaction_delay_reaches_the_run_and_its_certificate(tmp_path, capsys):
    rc, out = _run(tmp_path, "o", "--reaction-delay", "0.2")
    text = capsys.readouterr().out
    assert rc == 0 and "reaction delay θ_r = 0.2 s" in text
    doc = json.loads((out / "metrics.json").read_text(encoding="utf-8"))
    assert doc["run"]["reaction_delay"] == 0.2
    # K = (1.2, 0.5, 0.6) is certified without θ_r, not at θ_r = 0.2 s
    assert doc["certificate"]["verdict"] == "not_certified" and doc["m_fss"] == 0.0


def test_radio_run_reports_what_the_radio_did(tmp_path, capsys):
    rc, out = _run(tmp_path, "o", "--message-period", "0.2", "--message-phase", "1", "--loss", "0.3",
                   "--burst", "2", "--stale-after", "0.4", "--fallback-gains", "1,0.8,0",
                   "--noise-gap", "0.1", "--noise-correlation", "1", "--noise-filter", "0.2",
                   "--radio-seed", "4")
    text = capsys.readouterr().out
    assert rc == 0 and "radio: messages every 0.2 s" in text and "time in fallback" in text
    doc = json.loads((out / "metrics.json").read_text(encoding="utf-8"))
    r = doc["run"]["radio"]
    assert (r["message_period"], r["message_phase"], r["loss"], r["burst"], r["stale_after"],
            r["fallback_gains"], r["seed"]) == (0.2, 1, 0.3, 2.0, 0.4, [1.0, 0.8], 4)
    s = doc["run"]["sensors"]
    assert (s["noise_gap"], s["noise_correlation"], s["noise_filter"], s["seed"]) == (0.1, 1.0, 0.2, 4)
    rad = doc["radio"]
    due = np.add(rad["messages_received"], rad["messages_lost"])
    assert due.tolist() == [100] * 3  # 201 steps, messages at the odd ones
    assert 0.15 < rad["loss_share"] < 0.45 and rad["fallback_share"] > 0
    # the same seed writes the same run
    rc, again = _run(tmp_path, "p", "--message-period", "0.2", "--message-phase", "1", "--loss", "0.3",
                     "--burst", "2", "--stale-after", "0.4", "--fallback-gains", "1,0.8,0",
                     "--noise-gap", "0.1", "--noise-correlation", "1", "--noise-filter", "0.2",
                     "--radio-seed", "4")
    capsys.readouterr()
    A, B = _arrays(out), _arrays(again)
    for k in A:
        np.testing.assert_array_equal(A[k], B[k])


@pytest.mark.parametrize("extra, message", [
    (["--message-period", "0.15"], "--message-period: message period must be a whole multiple (>= 1) of the step dt = 0.1 s; got 0.15 s"),
    (["--message-period", "-0.1"], "--message-period must be a finite number of seconds > 0; got '-0.1'"),
    (["--message-period", "nan"], "--message-period must be a finite number of seconds > 0; got 'nan'"),
    (["--loss", "1.5"], "--loss must be a number in [0, 1]; got '1.5'"),
    (["--loss", "-0.01"], "--loss must be a number in [0, 1]; got '-0.01'"),
    (["--loss", "nan"], "--loss must be a number in [0, 1]; got 'nan'"),
    (["--noise-gap", "-0.1"], "--noise-gap must be a finite number >= 0; got '-0.1'"),
    (["--noise-gap-rate", "nan"], "--noise-gap-rate must be a finite number >= 0; got 'nan'"),
    (["--noise-speed", "x"], "--noise-speed must be a finite number >= 0; got 'x'"),
    (["--burst", "3"], "--burst needs --loss"),
    (["--loss", "0.1", "--burst", "0.5"], "--burst must be a finite number >= 1; got '0.5'"),
    (["--message-phase", "1"], "--message-phase needs --message-period"),
    (["--message-period", "0.2", "--message-phase", "2"], "--message-phase must be a step in 0..1"),
    (["--stale-after", "0.5", "--fallback-gains", "1"], "--fallback-gains must be K_X,K_V"),
    (["--stale-after", "0.5", "--fallback-gains", "1,1,0.5"], "--fallback-gains must be K_X,K_V"),
    (["--message-period", "0.5", "--stale-after", "0.2"], "--stale-after 0.2 s is shorter than the message period 0.5 s"),
    (["--noise-correlation", "1"], "--noise-correlation colours the noise"),
    (["--radio-seed", "1"], "--radio-seed seeds the message loss"),
    (["--reaction-delay", "-0.1"], "--reaction-delay (reaction delay θ_r) must be a finite number >= 0 s; got '-0.1'"),
    (["--reaction-delay", "nan"], "--reaction-delay (reaction delay θ_r) must be a finite number >= 0 s; got 'nan'"),
    (["--reaction-delay", "101"], "--reaction-delay (reaction delay θ_r) = 101 s is far outside"),
])
def test_bad_input_is_one_line_and_exit_2(tmp_path, capsys, extra, message):
    rc, out = _run(tmp_path, "o", *extra)
    err = capsys.readouterr().err
    assert rc == 2
    assert err.count("\n") == 1 and message in err, err
    assert not out.exists()


def _identify_json(path, **extra):
    row = {"position": 1, "name": "car1", "k_x": 0.9, "k_v": 0.7, "k_a": 0.2, "tau": 0.1, "delta": 0.2,
           "headway": 1.1, "standstill": 2.0, **extra}
    path.write_text(json.dumps({"command": "identify", "vehicles": [row]}), encoding="utf-8")
    return path


def test_from_identify_carries_the_fitted_reaction_delay(tmp_path, capsys):
    fitted = _identify_json(tmp_path / "with.json", reaction_delay=0.3)
    rc = main(["simulate", "--from", str(fitted), *BASE, "--out", str(tmp_path / "a")])
    assert rc == 0
    doc = json.loads((tmp_path / "a" / "metrics.json").read_text(encoding="utf-8"))
    assert doc["run"]["reaction_delay"] == 0.3 and doc["certificate"]["reaction_delay"] == 0.3
    plain = _identify_json(tmp_path / "without.json")  # a file written before θ_r was fitted
    rc = main(["simulate", "--from", str(plain), *BASE, "--out", str(tmp_path / "b")])
    assert rc == 0
    doc = json.loads((tmp_path / "b" / "metrics.json").read_text(encoding="utf-8"))
    assert "reaction_delay" not in doc["run"] and "reaction_delay" not in doc["certificate"]
    rc = main(["simulate", "--from", str(fitted), "--reaction-delay", "0.1", *BASE, "--out", str(tmp_path / "c")])
    err = capsys.readouterr().err
    assert rc == 2 and "takes the reaction delay of the fit (0.3 s); expected no --reaction-delay" in err


def test_report_shows_the_reaction_delay_the_radio_and_the_sensors(tmp_path, capsys):
    rc, out = _run(tmp_path, "o", "--reaction-delay", "0.1", "--message-period", "0.2", "--loss", "0.1",
                   "--stale-after", "0.4", "--noise-gap", "0.05", "--radio-seed", "3")
    capsys.readouterr()
    assert rc == 0
    doc = json.loads((out / "metrics.json").read_text(encoding="utf-8"))
    rows = {line.split(" | ")[0].lstrip("| "): line for line in
            (out / "report.md").read_text(encoding="utf-8").splitlines() if line.startswith("| ")}
    assert rows["reaction_delay"] == "| reaction_delay | 0.1 |"
    assert rows["radio"] == ("| radio | message_period = 0.2, message_phase = 0, loss = 0.1, "
                             "stale_after = 0.4, seed = 3 |")
    assert rows["sensors"].startswith("| sensors | noise_gap = 0.05, ")
    cert = next(v for k, v in rows.items() if k.startswith("K = (1.2, 0.5, 0.6) certified"))
    assert "reaction delay θ_r = 0.1 s" in cert and doc["certificate"]["verdict"] == "certified"
    assert "scope: the continuous-time loop" in cert and "covered by no certificate" in cert
    rad = doc["radio"]
    received = sum(rad["messages_received"])
    assert rows["the radio"] == (f"| the radio | **finding** | {received} messages received, "
                                 f"{100 * rad['loss_share']:.2f} % lost; time in fallback "
                                 f"{100 * rad['fallback_share']:.2f} % of follower time |")
    assert 0 < rad["loss_share"] < 0.3 and received > 200  # 3 followers × 100 messages due
    plain = tmp_path / "p"
    assert main(["simulate", *BASE, "--out", str(plain)]) == 0
    capsys.readouterr()
    rows = {line.split(" | ")[0].lstrip("| ") for line in
            (plain / "report.md").read_text(encoding="utf-8").splitlines() if line.startswith("| ")}
    assert {"tau", "delta", "model"} <= rows and not rows & {"reaction_delay", "radio", "sensors", "the radio"}
