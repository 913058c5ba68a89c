"""The reaction delay θ_r on `stringstab region` (issue 25 part 2): one θ_r, θ_r as a map axis.

Independent truths: the map with ``--reaction-delay 0`` against the map of the command without
the flag (bit for bit); the per-θ_r shares of a sweep against separate single-θ_r maps; the
certified points of a θ_r map against a fine frequency sweep of |Γ(jω)| written here from the
model of issue 25 (complex arithmetic, not the generated code); with ``--sample-time`` (issue 25
item 3), the point certificates and, for θ_r and δ whole numbers of steps, a fine sweep of the
sampled loop's H(e^{jθ}) built here from scipy's expm (the command shifted by θ_r/H steps).
"""

from __future__ import annotations

import csv

import numpy as np
import pytest
from scipy.linalg import expm

import stringstab as ss
from stringstab.certify.verdicts import codes
from stringstab.cli import main
from stringstab.regions import load_npz, reaction_sweep, region_map
from stringstab.regions.reaction_sweep import parse_reaction_delays

P = {"tau": 0.1, "delta": 0.2, "headway": 1.1}
BASE = ["region", "--fix", "k_a=0.5", "--n", "7", "--format", "png", "--dpi", "20",
        "--no-progress"]


def gamma_abs(omega, kx, kv, ka, *, tau, delta, headway, theta):
    """|Γ(jω)| of issue 25's model, from its transfer function in complex arithmetic."""
    s = 1j * np.asarray(omega)
    num = np.exp(-theta * s) * (kx + kv * s + ka * s**2 * np.exp(-delta * s))
    den = tau * s**3 + s**2 + np.exp(-theta * s) * ((kx * headway + kv) * s + kx)
    return np.abs(num / den)


def _files(out):
    return {p.name: p for p in out.iterdir()}


@pytest.mark.slow  # 20.3 s alone at load ≈ 24 on 2 shared cores (two CLI runs with figures)
def test_reaction_delay_zero_writes_what_the_command_without_it_writes(tmp_path, capsys):
    a, b = tmp_path / "a", tmp_path / "b"
    assert main([*BASE, "--out", str(a)]) == 0
    out_a = capsys.readouterr().out
    assert main([*BASE, "--reaction-delay", "0", "--out", str(b)]) == 0
    out_b = capsys.readouterr().out
    assert out_a.replace(str(a), "DIR") == out_b.replace(str(b), "DIR")
    fa, fb = _files(a), _files(b)
    assert set(fa) == set(fb)
    assert fa["region.csv"].read_bytes() == fb["region.csv"].read_bytes()
    ma, mb = load_npz(fa["region.npz"]), load_npz(fb["region.npz"])
    assert ma.metadata() == mb.metadata() and "reaction_delay" not in ma.metadata()["params"]
    for k, v in ma.fields().items():
        assert np.array_equal(v, mb.fields()[k], equal_nan=True), k


def test_one_reaction_delay_maps_the_certificate_with_it(tmp_path, capsys):
    out = tmp_path / "m"
    assert main([*BASE, "--reaction-delay", "0.2", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    head = text.splitlines()[0]
    assert head.endswith("τ = 0.1 s, δ = 0.2 s, T* = 1.1 s, θ_r = 0.2 s"), head
    m = load_npz(out / "region.npz")
    assert m.metadata()["params"] == {**P, "reaction_delay": 0.2}
    assert m.methods == ("exact",) and m.type is None
    kx, kv, ka = (g.ravel() for g in m.gains())
    ref = ss.certify_batch(kx, kv, ka, **P, reaction_delay=0.2)
    assert np.array_equal(m.verdict["exact"].ravel(), codes(ref.verdict))
    zero = ss.certify_batch(kx, kv, ka, **P)
    assert (zero.verdict == "certified").sum() > (ref.verdict == "certified").sum()
    # independent: every certified point has |Γ(jω)| ≤ 1 on a fine sweep (closed form)
    w = np.linspace(1e-4, 30.0, 30_001)
    for i in np.flatnonzero(ref.verdict == "certified"):
        peak = gamma_abs(w, kx[i], kv[i], ka[i], **P, theta=0.2).max()
        assert peak <= 1.0 + 1e-9, (kx[i], kv[i], ka[i], peak)
    for i in np.flatnonzero((ref.verdict == "not_certified") & ref.stable):
        peak = gamma_abs(w, kx[i], kv[i], ka[i], **P, theta=0.2).max()
        assert peak > 1.0, (kx[i], kv[i], ka[i], peak)  # the certificate's witness is real
    assert {"region_class_exact.png", "region_sup_gain.png", "region.csv"} <= set(_files(out))


def test_parse_reaction_delays():
    np.testing.assert_allclose(parse_reaction_delays("0:0.3:7"), np.linspace(0, 0.3, 7),
                               rtol=0, atol=1e-12)
    assert parse_reaction_delays("0:0.3:4").tolist() == parse_reaction_delays("0,0.1,0.2,0.3").tolist()
    assert parse_reaction_delays("0.1,0.2").tolist() == [0.1, 0.2]
    assert parse_reaction_delays("0.2") is None and parse_reaction_delays("0.1:0.3") is None


# the IDL grid case: an 11³ sub-lattice of the 81³ grid of docs/theory.md over [−2, 2]³
IDL_AXES = {g: np.linspace(-2.0, 2.0, 11) for g in ("k_x", "k_v", "k_a")}
THETAS = [0.0, 0.1, 0.2, 0.3]


def test_sweep_shares_equal_single_maps_and_do_not_increase_on_the_idl_grid():
    s = reaction_sweep(IDL_AXES, reaction_delays=THETAS, **P, workers=1, progress=False)
    shares = s.certified_shares()
    for th, share, m in zip(THETAS, shares, s.maps):
        single = region_map(IDL_AXES, **P, methods="exact", reaction_delay=th, workers=1,
                            progress=False)
        assert np.array_equal(single.verdict["exact"], m.verdict["exact"])
        assert share == single.verdict_shares()["exact"]["certified"]
    assert shares[0] > 0.05  # a region to lose (≈ 9 % on the 81³ grid)
    assert np.all(np.diff(shares) <= 0), shares  # non-increasing on this grid
    assert np.all(np.diff(shares) < 0), shares  # ... and strictly here
    # nested, too: no triple certified at a larger θ_r that was not at the smaller one
    for a, b in zip(s.maps, s.maps[1:]):
        assert not np.any(b.stable("exact") & ~a.stable("exact"))


@pytest.mark.slow  # 17.5 s alone at load ≈ 24 on 2 shared cores (two CLI runs with figures)
def test_cli_sweep_writes_slices_table_and_figure(tmp_path, capsys):
    out = tmp_path / "sweep"
    assert main([*BASE, "--reaction-delay", "0:0.2:3", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    files = _files(out)
    for th in ("0", "0.1", "0.2"):
        assert f"region_theta_r_{th}.npz" in files and f"region_theta_r_{th}_class_exact.png" in files
    assert "region_share_vs_theta_r.png" in files and "report.md" in files
    with open(files["region_share_vs_theta_r.csv"], newline="") as fh:
        rows = list(csv.DictReader(r for r in fh if not r.startswith("#")))
    assert [float(r["reaction_delay"]) for r in rows] == [0.0, 0.1, 0.2]
    axes = {"k_x": np.linspace(-2, 2, 7), "k_v": np.linspace(-2, 2, 7)}
    for r in rows:
        th = float(r["reaction_delay"])
        single = region_map(axes, {"k_a": 0.5}, **P, methods="exact", reaction_delay=th,
                            workers=1, progress=False)
        assert float(r["certified_share"]) == single.verdict_shares()["exact"]["certified"]
        assert int(r["certified"]) == int(single.stable("exact").sum())
        m = load_npz(files[f"region_theta_r_{th:g}.npz"])
        assert np.array_equal(m.verdict["exact"], single.verdict["exact"])
        assert m.metadata()["params"] == ({**P, "reaction_delay": th} if th else P)
    assert "certified share vs θ_r:" in text


@pytest.mark.parametrize(
    "argv,match",
    [
        (["--reaction-delay", "-0.1"], "reaction delay θ_r"),
        (["--reaction-delay", "nan"], "reaction delay θ_r"),
        (["--reaction-delay", "101"], "reaction"),
        # a point θ_r with --sample-time (and --message-period) is mapped (below); a box of
        # θ_r with a sample time is refused, before any work
        (["--reaction-delay", "0.1:0.3", "--sample-time", "0.1"],
         "over a parameter box is certified in continuous time only"),
        (["--reaction-delay", "0.2", "--tau", "0.1:0.2", "--sample-time", "0.1"],
         "over a parameter box is certified in continuous time only"),
        (["--reaction-delay", "0,0.2", "--tau", "0.1:0.2", "--sample-time", "0.1"],
         "over a parameter box is certified in continuous time only"),
        (["--reaction-delay", "0,0.2", "--sample-time", "0.1", "--compare", "continuous"],
         "evaluates 'exact'"),
        # a box with θ_r (--tau 0.1:0.2 with θ_r, --reaction-delay 0.1:0.3) is mapped by the
        # θ_r box certificate: tests/certify/test_robust_reaction.py
        (["--reaction-delay", "0,0.2", "--delta", "0.1:0.2"], "needs one τ, δ, T*"),
        (["--reaction-delay", "0,-0.2"], "reaction delay θ_r"),
        (["--reaction-delay", "0.2,0.1"], "strictly increasing"),
        (["--reaction-delay", "0:0.3:1"], "N >= 2"),
        (["--reaction-delay", "0:0.3:x"], "count N"),
        (["--reaction-delay", "0.2", "--method", "taylor"], "without reaction delay"),
        (["--reaction-delay", "0,0.2", "--method", "exact,taylor"], "evaluates 'exact'"),
        (["--reaction-delay", "0.2", "--overlay", "x.csv"], "--overlay"),
    ],
)
def test_bad_reaction_delay_exits_2_with_one_line_and_writes_nothing(tmp_path, capsys, argv, match):
    out = tmp_path / "maps"
    assert main([*BASE, *argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("stringstab region: error:") and match in err, err
    assert err.count("\n") == 1
    assert not out.exists()


# --------------------------------------------------------------------------- θ_r with a sample time
def sampled_abs(theta, kx, kv, ka, *, tau, delta, headway, H, reaction_delay):
    """|H(e^{jθ})| of the sampled loop (ZOH, period H) with θ_r = qH and δ = mH, from expm.

    The command held over step k is u_{k−q}; the vehicle's P(z) over a held step is
    (zI − Φ)⁻¹Γ, so the loop is the sampled one with P(z) z^{−q} (the shift by q steps).
    """
    q, m = round(reaction_delay / H), round(delta / H)
    assert abs(q * H - reaction_delay) < 1e-12 and abs(m * H - delta) < 1e-12
    M = np.zeros((4, 4))
    M[0, 1] = M[1, 2] = 1.0
    M[2, 2], M[2, 3] = -1.0 / tau, 1.0 / tau
    E = expm(M * H)
    Phi, G = E[:3, :3], E[:3, 3]
    z = np.exp(1j * np.asarray(theta))
    X = np.array([np.linalg.solve(zz * np.eye(3) - Phi, G) for zz in z]) * (z ** -q)[:, None]
    Pp, Pv, Pa = X[:, 0], X[:, 1], X[:, 2]
    num = kx * Pp + kv * Pv + ka * Pa * z ** (-m)
    return np.abs(num / (1.0 + kx * (Pp + headway * Pv) + kv * Pv))


SAMPLED = ["--range", "k_x=0.1,1.5", "--range", "k_v=0,1.5", "--n", "5", "--sample-time", "0.1"]


def test_a_reaction_delay_with_a_sample_time_maps_the_sampled_certificate(tmp_path, capsys):
    # issue 25 item 3: once refused, now the sampled θ_r certificate on a coarse grid
    out = tmp_path / "m"
    argv = [a for a in BASE if a not in ("--n", "7")]
    assert main([*argv, *SAMPLED, "--reaction-delay", "0.2", "--compare", "continuous",
                 "--out", str(out)]) == 0
    head = capsys.readouterr().out.splitlines()[0]
    assert "θ_r = 0.2 s" in head and "sampled Δt = 0.1 s" in head, head
    m = load_npz(out / "region.npz")
    assert m.sample_time == 0.1 and m.methods == ("exact", "continuous")
    assert m.metadata()["params"] == {**P, "reaction_delay": 0.2}
    kx, kv, ka = (g.ravel() for g in m.gains())
    opts = {**P, "sample_time": 0.1, "reaction_delay": 0.2}
    ref = ss.certify_batch(kx, kv, ka, **opts)
    assert np.array_equal(m.verdict["exact"].ravel(), codes(ref.verdict))
    assert np.array_equal(m.hurwitz.ravel(), np.asarray(ref.stable))
    assert np.array_equal(m.verdict["exact"].ravel(), codes(ss.check(kx, kv, ka, **opts).verdict))
    # the comparison is the continuous loop with the same θ_r, not the loop without it
    cont = ss.certify_batch(kx, kv, ka, **P, reaction_delay=0.2)
    assert np.array_equal(m.verdict["continuous"].ravel(), codes(cont.verdict))
    assert 0 < (ref.verdict == "certified").sum() < kx.size  # the grid crosses the boundary
    # independent: H(e^{jθ}) of the loop built here from expm, on a fine θ grid
    th = np.linspace(1e-4, np.pi, 4001)
    for i in range(kx.size):
        peak = sampled_abs(th, kx[i], kv[i], ka[i], **P, H=0.1, reaction_delay=0.2).max()
        if ref.verdict[i] == "certified":
            assert peak <= 1.0 + 1e-9, (kx[i], kv[i], ka[i], peak)
        elif ref.stable[i] and ref.verdict[i] == "not_certified":
            assert peak > 1.0 - 1e-9, (kx[i], kv[i], ka[i], peak)  # its witness is real
    assert {"region_class_exact.png", "region_compare.png", "region.csv"} <= set(_files(out))


def test_a_sampled_sweep_over_reaction_delays_equals_its_single_maps():
    axes = {"k_x": np.linspace(0.1, 1.5, 4), "k_v": np.linspace(0.0, 1.5, 4)}
    s = reaction_sweep(axes, {"k_a": 0.5}, reaction_delays=[0.0, 0.2], **P, sample_time=0.1,
                       workers=1, progress=False)
    assert s.summary()["sample_time"] == 0.1
    plain = region_map(axes, {"k_a": 0.5}, **P, sample_time=0.1, workers=1, progress=False)
    assert np.array_equal(s.maps[0].verdict["exact"], plain.verdict["exact"])  # θ_r = 0: today's
    single = region_map(axes, {"k_a": 0.5}, **P, sample_time=0.1, reaction_delay=0.2,
                        workers=1, progress=False)
    assert np.array_equal(s.maps[1].verdict["exact"], single.verdict["exact"])
    assert s.maps[1].sample_time == 0.1 and s.maps[1].params.reaction_delay == 0.2


def test_a_reaction_delay_with_a_message_period_maps_the_multirate_certificate():
    # θ_r with the radio's message period (issue 25): the map is the point certificate's
    axes = {"k_x": np.linspace(0.1, 1.5, 3), "k_v": np.linspace(0.2, 1.5, 3)}
    opts = {**P, "sample_time": 0.05, "message_period": 0.1, "reaction_delay": 0.2}
    m = region_map(axes, {"k_a": 0.5}, **opts, workers=1, progress=False)
    kx, kv, ka = (g.ravel() for g in m.gains())
    ref = ss.certify_batch(kx, kv, ka, **opts)
    assert np.array_equal(m.verdict["exact"].ravel(), codes(ref.verdict))
    assert m.message_period == 0.1 and m.params.reaction_delay == 0.2
