"""SUMO's CACC model as per-mode linear laws: derivation checked against SUMO, certificates
against closed forms and time-domain iteration (SUMO parts skipped without the extra)."""

from __future__ import annotations

import json
import math
import os

import pytest

from stringstab.errors import StringStabError
from stringstab.sumo import runtime
from stringstab.sumo.cacc import certify_modes, discrete_sweep, mode_laws, read_vtype

DATA = os.path.join(os.path.dirname(runtime.__file__), "..", "data", "sumo", "cacc.rou.xml")


def test_mode_laws_of_the_default_type():
    vt = read_vtype(f"{DATA}:cacc")
    assert (vt.headway, vt.min_gap, vt.length) == (1.0, 2.5, 5.0)
    laws = {law.mode: law for law in mode_laws(vt, 0.1)}
    # u = (g_s e + g_d (dv - T u)) / 0.1  =>  k_x = 10 g_s / (1 + 10 g_d T), k_v = 10 g_d / (...)
    for mode, (gs, gd) in {"gap control": (0.45, 0.0125), "gap closing": (0.005, 0.05),
                           "collision avoidance": (0.45, 0.05)}.items():
        law = laws[mode]
        assert law.k_x == pytest.approx(10 * gs / (1 + 10 * gd))
        assert law.k_v == pytest.approx(10 * gd / (1 + 10 * gd))
    # SUMO scales a step shorter than 0.1 s to 0.1 s; a longer one uses the step itself
    assert mode_laws(vt, 0.05)[0].k_p == pytest.approx(4.5)
    assert mode_laws(vt, 0.2)[0].k_p == pytest.approx(2.25)


def test_certificates_match_the_no_lag_closed_form():
    for tid in ("cacc", "cacc_t14"):
        for row in certify_modes(read_vtype(f"{DATA}:{tid}"), 0.1):
            closed = row["no_lag_closed_form"]["string_stable"]
            assert (row["continuous"]["verdict"] == "certified") == closed, (tid, row["mode"])
            assert (row["sampled"]["verdict"] == "certified") == closed, (tid, row["mode"])
    gap_closing = certify_modes(read_vtype(f"{DATA}:cacc"), 0.1)[1]
    assert gap_closing["mode"] == "gap closing"
    assert gap_closing["continuous"]["verdict"] == "not_certified"


def _iterate(law, dt=0.1, steps=3000):
    """SUMO's per-mode law frozen, a follower behind a constant-speed leader, by iteration."""
    T, L = law.headway, 5.0
    v = vl = 20.0
    x, xl = 0.0, law.standstill + T * v + L + 0.5
    a_prev = 0.0
    errs = []
    for _ in range(steps):
        e = (xl - x - L) - law.standstill - T * v
        u = law.k_p * e + law.k_d * ((vl - v) - T * a_prev)
        x += v * dt + 0.5 * u * dt * dt
        v += u * dt
        xl += vl * dt
        a_prev = u
        errs.append(abs(e))
    return errs


def test_discrete_sweep_against_time_domain_iteration():
    unstable = 0
    for tid in ("cacc", "cacc_t14"):
        for law in mode_laws(read_vtype(f"{DATA}:{tid}"), 0.1):
            sw = discrete_sweep(law, 0.1)
            errs = _iterate(law)
            if sw["schur"]:
                assert errs[-1] < 1e-6 * errs[0]
            else:
                unstable += 1
                growth = (errs[-1] / errs[-201]) ** (1 / 200)
                assert growth == pytest.approx(sw["spectral_radius"], rel=1e-2)
    assert unstable == 1  # collision avoidance at T = 1.4 s: the own-acceleration term at 0.1 s


def test_bad_vtypes(tmp_path):
    with pytest.raises(StringStabError, match=r"FILE\.rou\.xml:TYPE"):
        read_vtype(DATA)
    with pytest.raises(StringStabError, match="does not exist"):
        read_vtype(f"{tmp_path / 'x.rou.xml'}:cacc")
    with pytest.raises(StringStabError, match="no vType 'nope'"):
        read_vtype(f"{DATA}:nope")
    f = tmp_path / "k.rou.xml"
    f.write_text('<routes><vType id="k" tau="1"/><vType id="b" carFollowModel="CACC" tau="x"/></routes>')
    with pytest.raises(StringStabError, match="expected carFollowModel=\"CACC\""):
        read_vtype(f"{f}:k")
    with pytest.raises(StringStabError, match="tau must be a number"):
        read_vtype(f"{f}:b")


@pytest.mark.parametrize("dt", ["0.1", "0.05", "0.2"])  # SUMO scales the gains by max(dt, 0.1 s)
def test_derived_law_reproduces_sumo_and_cli(tmp_path, capsys, dt):
    pytest.importorskip("libsumo", reason="needs the optional extra 'sumo' (pip install 'stringstab[sumo]')")
    from stringstab.cli import main

    out = tmp_path / "cacc.json"
    rc = main(["sumo", "cacc", "--vtype", f"{DATA}:cacc", "--followers", "4", "--duration", "40",
               "--dt", dt, "--json", str(out)])
    text = capsys.readouterr().out
    assert rc == 0, text
    assert "does not certify the switched law" in text
    doc = json.loads(out.read_text())
    res = doc["platoon"]["law_residual"]
    assert sum(r["steps"] for r in res.values()) > 100
    for r in res.values():  # every mode SUMO used is the derived law, to round-off
        assert r["steps"] == 0 or r["max_residual"] < 1e-9
    assert len(doc["platoon"]["m_p"]) == 4 and all(math.isfinite(m) for m in doc["platoon"]["m_p"])
