"""``stringstab identify`` end to end on a simulated log, ``certify --from`` and ``simulate --from``
on its identify.json, and the bad inputs of issue 16 (one line, exit 2, nothing written)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from stringstab.cli import main
from stringstab.traffic import LinearController, from_speed, simulate


def _csv(path: Path, *, duration: float = 150.0, mutate=None) -> Path:
    """t, v0, v1, gap1, v2, gap2 of a simulated platoon: a string-stable car then an unstable one."""
    t = np.arange(0.0, duration + 0.05, 0.1)
    lead = from_speed(t, 15 + 3 * np.sin(2 * np.pi * t / 50) + np.sin(0.5 * t), dt=0.1)
    c = LinearController([0.2, 0.3], [0.7, 0.2], [0.0, 0.0], headway=1.5, standstill=4.0)
    r = simulate(lead, c, 2, tau=np.array([0.3, 0.6]), delta=0.0)
    cols = [t, r.speed[0], r.speed[1], r.gap[0], r.speed[2], r.gap[1]]
    header = ["t", "v0", "v1", "gap1", "v2", "gap2"]
    if mutate is not None:
        header, cols = mutate(header, [c.copy() for c in cols])
    rows = [",".join(header)] + [",".join("" if not math.isfinite(x) else f"{x:.6f}" for x in row)
                                 for row in np.column_stack(cols)]
    path.write_text("\n".join(rows) + "\n")
    return path


def test_identify_cli_end_to_end(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    log = _csv(tmp_path / "log.csv")
    out = tmp_path / "run"
    # θ_r not fitted here (--fit-delay below): on a noise-free log with θ_r = 0 its fit creeps
    # along the bound θ_r = 0 for hundreds of evaluations
    rc = main(["identify", str(log), "--bootstrap", "2", "--starts", "1", "--no-fit-delay", "--no-progress",
               "--out", str(out)])
    text = capsys.readouterr().out
    assert rc == 0
    names = {p.name for p in out.iterdir()}
    assert {"identify.json", "identify.csv", "identify.parquet", "fit_1.png", "fit_2.png",
            "transfer_1.png", "transfer_2.png", "sup_gain.png", "report.md", "report.html"} <= names
    # the report: every figure embedded as a data: URI, nothing loaded from the network
    import base64
    import re

    md = (out / "report.md").read_text(encoding="utf-8")
    html = (out / "report.html").read_text(encoding="utf-8")
    pngs = sorted(p.name for p in out.glob("*.png"))
    assert all(f"]({p})" in md for p in pngs)
    srcs = re.findall(r'<img\b[^>]*\bsrc="([^"]+)"', html)
    assert all(s.startswith("data:image/png;base64,") for s in srcs)
    assert sorted(base64.b64decode(s.split(",", 1)[1]) for s in srcs) == sorted(
        (out / p).read_bytes() for p in pngs)
    assert not re.search(r'(?:src|href)="https?://', html)
    assert "vehicle2: fitted gains certified string stable" in md and "2 of 2 bootstrap fits" in md
    assert "The data's own amplification" in md
    doc = json.loads((out / "identify.json").read_text())
    rows = doc["vehicles"]
    assert [r["position"] for r in rows] == [1, 2] and rows[0]["name"] == "vehicle1"
    for k in ("k_x", "k_v", "k_a", "tau", "delta", "headway", "standstill", "rmse_speed", "rmse_gap",
              "sup_gain", "peak_omega", "verdict", "certified_share", "empirical_gain", "segments"):
        assert k in rows[0]
    assert [r["verdict"] for r in rows] == ["certified", "not_certified"]
    assert rows[1]["statement"] == "not string stable in 2 of 2 bootstrap fits"
    assert "not string stable in 2 of 2 bootstrap fits" in text
    csv_head = (out / "identify.csv").read_text().splitlines()[0].split(",")
    assert {"position", "name", "k_x", "verdict", "certified_share"} <= set(csv_head)

    # certify --from: the same verdicts and sup|Γ| from the certifier on the fitted parameters
    rc = main(["certify", "--from", str(out / "identify.json"), "--format", "json"])
    cert = json.loads(capsys.readouterr().out)["results"]
    assert rc == 1  # one vehicle not certified
    assert [c["verdict"] for c in cert] == [r["verdict"] for r in rows]
    assert cert[1]["sup_gain"] == pytest.approx(rows[1]["sup_gain"], rel=1e-9)

    # simulate --from: the unstable car in a longer platoon
    rc = main(["simulate", "--from", str(out / "identify.json"), "--vehicle", "2", "--followers", "4",
               "--leader", "sinusoid:omega=0.5", "--duration", "30", "--dt", "0.05", "--no-figures",
               "--out", str(tmp_path / "sim")])
    assert rc == 0
    metrics = json.loads((tmp_path / "sim" / "metrics.json").read_text())
    assert metrics["run"]["k_x"] == pytest.approx(rows[1]["k_x"])
    assert metrics["run"]["tau"] == pytest.approx(rows[1]["tau"])


def _one_vehicle(h, c):
    return h[:2], c[:2]


def _all_nan(h, c):
    c[4][:] = np.nan
    return h, c


def _negative(h, c):
    c[2][100] = -5.0
    return h, c


def _absurd(h, c):
    c[2][100] = 500.0
    return h, c


def _no_gap(h, c):
    return h[:3] + h[4:5], c[:3] + c[4:5]


def _time_back(h, c):
    c[0][10] = c[0][9]
    return h, c


def _dropouts(h, c):
    for k in (1, 2, 4):  # two samples every 5 s: no clean segment of 30 s (one would be bridged)
        c[k][::50] = np.nan
        c[k][1::50] = np.nan
    return h, c


@pytest.mark.parametrize(("mutate", "args", "message"), [
    (_one_vehicle, [], "expected columns|expected speed columns"),
    (_all_nan, [], "empty or NaN in every row"),
    (_negative, [], "must be >= 0 m/s"),
    (_absurd, [], "absurd"),
    (_no_gap, [], "expected gap columns|predecessor and a follower"),
    (_time_back, [], "time must increase strictly"),
    (_dropouts, [], "no follower has a usable segment"),
    (None, ["--model", "cacc"], "needs the predecessor's acceleration"),
    (None, ["--bootstrap", "-1"], "--bootstrap must be an integer >= 0"),
    (None, ["--sample-time", "0"], "--sample-time must be a number of seconds > 0"),
])
def test_identify_bad_input(tmp_path: Path, capsys: pytest.CaptureFixture[str], mutate, args, message) -> None:
    log = _csv(tmp_path / "log.csv", duration=60.0, mutate=mutate)
    out = tmp_path / "run"
    rc = main(["identify", str(log), "--bootstrap", "0", "--starts", "1", "--no-fit-delay", "--no-figures",
               "--no-progress",
               *args, "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 2
    lines = [x for x in err.splitlines() if x.strip()]
    assert len(lines) == 1 and lines[0].startswith("stringstab identify: error: ")
    import re

    assert re.search(message, lines[0]), lines[0]
    assert not out.exists()  # nothing written


def test_identify_fit_delay_cli(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """--fit-delay (the default in continuous time) on a noisy log of a car with θ_r = 0.4 s:
    θ_r recovered within 0.1 s, its interval and profile in identify.json, the certificate at that
    θ_r, certify --from re-certifies each vehicle at its own θ_r (same verdict and sup|Γ|), and
    simulate --from runs a platoon of that car at its θ_r."""

    import stringstab as ss
    from stringstab.identify import FollowerModel
    from tests.identify_sim import car_log

    lg = car_log(FollowerModel(0.2, 0.5, 0.0, 0.3, 0.0, 1.2, 4.0, 0.4), (12, 20, 9, 16), ramp=4.0, seed=3)
    t = lg.t
    path = tmp_path / "delayed.csv"
    rows = ["t,v_lead,v,gap"] + [f"{t[k]:.1f},{lg.speed[0, k]:.5f},{lg.speed[1, k]:.5f},{lg.gap[1][k]:.4f}"
                                 for k in range(t.size)]
    path.write_text("\n".join(rows) + "\n")
    out = tmp_path / "run"
    assert main(["identify", str(path), "--bootstrap", "2", "--starts", "1", "--no-figures", "--no-progress",
                 "--out", str(out)]) == 0
    capsys.readouterr()
    [r] = json.loads((out / "identify.json").read_text())["vehicles"]
    assert abs(r["reaction_delay"] - 0.4) < 0.1
    assert math.isfinite(r["reaction_delay_lo"]) and r["reaction_delay_lo"] <= r["reaction_delay_hi"]
    assert [p["reaction_delay"] for p in r["delay_profile"]] == [0.0, 0.2, 0.4, 0.6, 0.8, 1.0, 1.5]
    c = ss.certify(r["k_x"], r["k_v"], r["k_a"], tau=r["tau"], delta=r["delta"], headway=r["headway"],
                   reaction_delay=r["reaction_delay"])
    assert c.verdict == r["verdict"] and float(c.sup_gain) == pytest.approx(r["sup_gain"], rel=1e-12)
    # the box certificate now covers θ_r's bootstrap interval too (issue 25, item 4)
    assert r["box_verdict"] in ("certified", "not_certified", "inconclusive")
    main(["certify", "--from", str(out / "identify.json"), "--format", "json"])
    [cr] = json.loads(capsys.readouterr().out)["results"]
    assert cr["verdict"] == r["verdict"] and cr["sup_gain"] == pytest.approx(r["sup_gain"], rel=1e-9)
    assert main(["simulate", "--from", str(out / "identify.json"), "--vehicle", "1", "--no-figures",
                 "--leader", "sinusoid:omega=0.3,amplitude=1", "--duration", "20", "--followers", "2",
                 "--out", str(tmp_path / "sim")]) == 0
    sim = json.loads((tmp_path / "sim" / "metrics.json").read_text(encoding="utf-8"))
    assert sim["run"]["reaction_delay"] == r["reaction_delay"]  # the fitted θ_r, simulated
    assert sim["certificate"]["reaction_delay"] == r["reaction_delay"]


def test_identify_fit_delay_with_a_sample_time(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """--sample-time with θ_r fitted (the default, issue 25): the verdict and sup|Γ| are the sampled
    certificate's with θ_r at the fitted parameters, sup|Γ| agrees with a fine sweep of the
    certificate's link |H(e^{jθ})| (an independent resolvent, no branch and bound), and
    ``certify --from --sample-time`` re-certifies the same; ``--no-fit-delay`` keeps θ_r = 0."""
    import stringstab as ss
    from stringstab.certify.lifting import lifted_response
    from stringstab.certify.lifting_reaction import lift_reaction
    from stringstab.identify import FollowerModel
    from stringstab.params import Params
    from tests.identify_sim import car_log

    lg = car_log(FollowerModel(0.2, 0.5, 0.0, 0.3, 0.0, 1.2, 4.0, 0.4), (12, 20, 9, 16), ramp=4.0, seed=3)
    t = lg.t
    path = tmp_path / "delayed.csv"
    rows = ["t,v_lead,v,gap"] + [f"{t[k]:.1f},{lg.speed[0, k]:.5f},{lg.speed[1, k]:.5f},{lg.gap[1][k]:.4f}"
                                 for k in range(t.size)]
    path.write_text("\n".join(rows) + "\n")
    out = tmp_path / "run"
    assert main(["identify", str(path), "--sample-time", "0.1", "--bootstrap", "2", "--starts", "1",
                 "--no-figures", "--no-progress", "--out", str(out)]) == 0
    capsys.readouterr()
    doc = json.loads((out / "identify.json").read_text())
    [r] = doc["vehicles"]
    assert abs(r["reaction_delay"] - 0.4) < 0.1
    H, theta = 0.1, r["reaction_delay"]
    c = ss.certify(r["k_x"], r["k_v"], r["k_a"], tau=r["tau"], delta=r["delta"], headway=r["headway"],
                   reaction_delay=theta, sample_time=H)
    assert c.verdict == r["verdict"] and float(c.sup_gain) == pytest.approx(r["sup_gain"], rel=1e-12)
    link = lift_reaction(np.array([r["k_x"]]), np.array([r["k_v"]]), np.array([r["k_a"]]),
                         Params(r["tau"], r["delta"], r["headway"], reaction_delay=theta), H, 1)
    sweep = np.abs(lifted_response(link, np.linspace(1e-4, np.pi, 20_001))[0, :, 0, 0]).max()
    assert sweep == pytest.approx(r["sup_gain"], rel=1e-4)
    assert (r["verdict"] == "not_certified") == (sweep > 1 + 1e-6)
    main(["certify", "--from", str(out / "identify.json"), "--sample-time", "0.1", "--format", "json"])
    [cr] = json.loads(capsys.readouterr().out)["results"]
    assert cr["verdict"] == r["verdict"] and cr["sup_gain"] == pytest.approx(r["sup_gain"], rel=1e-9)
    out2 = tmp_path / "run2"
    assert main(["identify", str(path), "--sample-time", "0.1", "--no-fit-delay", "--bootstrap", "0",
                 "--starts", "1", "--no-figures", "--no-progress", "--out", str(out2)]) == 0
    [r2] = json.loads((out2 / "identify.json").read_text())["vehicles"]
    assert r2.get("reaction_delay", 0.0) == 0.0
