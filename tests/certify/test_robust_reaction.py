"""The robust certificate over a box that includes the reaction delay θ_r (issue 25, item 4).

Truths used: the point certificate (``stringstab.certify`` at one θ_r) for boxes of zero width
and for the members of a box that contains a point it does not certify; |Γ(jω)| of the
transfer function written out in ``analysis/box_reaction_check.py`` (complex exponentials on a
dense grid) and its Padé(12, 12) root count, for every member of a grid over a certified box;
and a small seeded run of that script.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import stringstab as ss
from stringstab.certify import box_axis, robust, robust_continuous, robust_reaction
from stringstab.errors import StringStabError
from stringstab.params import Box, check_box

SCRIPT = Path(__file__).resolve().parents[2] / "analysis" / "box_reaction_check.py"
BUDGET = {"n_grid": 64, "max_rounds": 30, "max_intervals": 1024, "max_splits": 48,
          "max_cells": 4096}


@pytest.fixture(scope="module")
def check() -> Any:
    spec = importlib.util.spec_from_file_location("box_reaction_check", SCRIPT)
    assert spec and spec.loader
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_zero_width_box_equals_the_point_certificate() -> None:
    """A box of zero width in every parameter (through the cells' kernel, not the way in that
    would turn it into a point) gives the point certificate's verdict, triple by triple."""
    rng = np.random.default_rng(7)
    n = 40
    kx, kv, ka = rng.uniform(0.1, 1.5, n), rng.uniform(0.0, 2.0, n), rng.uniform(-0.5, 1.0, n)
    for tau, delta, headway, theta in [(0.15, 0.2, 1.1, 0.1), (0.3, 0.0, 2.0, 0.25),
                                       (0.1, 0.3, 1.5, 0.0)]:
        box = Box((tau, tau), (delta, delta), (headway, headway), (theta, theta))
        got = robust_reaction.certify_box_reaction(kx, kv, ka, box, **BUDGET)
        want = ss.check(kx, kv, ka, tau=tau, delta=delta, headway=headway, reaction_delay=theta)
        names = np.array(["certified", "not_certified", "inconclusive"])[got["verdict"]]
        assert names.tolist() == list(want.verdict)
        assert {"certified", "not_certified"} <= set(names.tolist())  # both kinds were compared


def test_box_containing_a_point_that_is_not_certified() -> None:
    """(1.2, 0.5, 0.6) at τ = 0.15, δ = 0.2, T* = 1.1 is certified at θ_r = 0.1 and not at
    θ_r = 0.15 (point certificate): the box θ_r ∈ [0.05, 0.3] is not certified, its witness is a
    member of the box that the point certificate does not certify, with |Γ| > 1 at the witness
    frequency (the transfer function written out)."""
    assert ss.certify(1.2, 0.5, 0.6, tau=0.15, delta=0.2, headway=1.1,
                      reaction_delay=0.1).verdict == "certified"
    assert ss.certify(1.2, 0.5, 0.6, tau=0.15, delta=0.2, headway=1.1,
                      reaction_delay=0.15).verdict == "not_certified"
    c = ss.certify(1.2, 0.5, 0.6, tau="0.1:0.2", delta=0.2, headway=1.1, reaction_delay="0.05:0.3")
    assert c.verdict == "not_certified" and c.stable
    assert 0.05 <= c.witness_reaction_delay <= 0.3 and 0.1 <= c.witness_tau <= 0.2
    member = dict(tau=c.witness_tau, delta=c.witness_delta, headway=c.witness_headway,
                  reaction_delay=c.witness_reaction_delay)
    assert ss.certify(1.2, 0.5, 0.6, **member).verdict == "not_certified"
    s, th = 1j * c.witness_omega, c.witness_reaction_delay
    e = np.exp(-th * s)
    gamma = abs(e * (1.2 + 0.5 * s + 0.6 * s * s * np.exp(-0.2 * s))
                / (c.witness_tau * s**3 + s * s + e * ((0.5 + c.witness_headway * 1.2) * s + 1.2)))
    assert gamma > 1.0
    assert c.sup_gain == pytest.approx(gamma, rel=1e-9)


def test_box_with_an_unstable_member(check: Any) -> None:
    """θ_r up to 2 s makes members unstable: not certified, and the witness member is unstable
    by the Padé(12, 12) root count (or its |Γ| exceeds 1)."""
    c = ss.certify(1.2, 0.5, 0.6, tau=0.15, delta=0.2, headway=1.1, reaction_delay="0.05:2")
    assert c.verdict == "not_certified"
    w = c.witness_omega
    if np.isfinite(w):
        g = check.gamma_abs(np.array([w]), 1.2, 0.5, 0.6, c.witness_tau, c.witness_delta,
                            c.witness_headway, c.witness_reaction_delay)[0]
        assert g > 1.0
    else:
        assert check.unstable_pade(1.2, 0.5, c.witness_tau, c.witness_headway,
                                   c.witness_reaction_delay)


def test_certified_box_members_pass_the_independent_check(check: Any) -> None:
    """A certified box: every member of a 4 × 3 × 3 × 4 grid (and the corners) is stable by the
    Padé root count and has sup|Γ| ≤ 1 + 1e-9 on the dense sweep."""
    iv = dict(tau=(0.1, 0.2), delta=(0.1, 0.3), headway=(1.0, 1.3), reaction_delay=(0.02, 0.08))
    c = ss.certify(1.2, 0.5, 0.6, **iv)
    assert c.verdict == "certified" and c.stable and c.sup_gain == 1.0
    grids = [np.linspace(lo, hi, k) for (lo, hi), k in zip(iv.values(), (4, 3, 3, 4))]
    members = np.array(np.meshgrid(*grids)).reshape(4, -1).T
    peaks, _ = check.peak_gain(1.2, 0.5, 0.6, members)
    assert peaks.max() <= 1.0 + 1e-9
    assert peaks.max() > 0.99  # |Γ| → 1 as ω → 0: the sweep saw the low frequencies
    assert not any(check.unstable_pade(1.2, 0.5, m[0], m[2], m[3]) for m in members)


def test_cell_cost_bounds_the_margin_over_a_cell() -> None:
    """The mean-value bound g_θ(ω; p) ≥ g_θ(ω; p_c) − Σ L_i r_i holds on a random grid of
    members and frequencies (g_θ from stringstab.certify.margin_reaction.g, at each member)."""
    from stringstab.certify.margin_reaction import g

    rng = np.random.default_rng(3)
    lo = np.array([0.1, 0.0, 0.8, 0.05])
    hi = np.array([0.4, 0.3, 1.6, 0.35])
    for _ in range(20):
        k = rng.uniform([0.1, -0.5, -1.0], [2.0, 2.0, 1.0])
        P = robust_reaction.cell_cost(*(np.array([v]) for v in k), lo[:, None], hi[:, None])
        w = rng.uniform(0.0, 6.0, 50)
        pc = 0.5 * (lo + hi)
        low = g(w, *k, tau=pc[0], delta=pc[1], headway=pc[2], reaction_delay=pc[3]) - sum(
            P[j, 0] * w**j for j in range(5))
        p = lo + (hi - lo) * rng.uniform(size=(200, 4))
        vals = g(w[None, :], *k, tau=p[:, :1], delta=p[:, 1:2], headway=p[:, 2:3],
                 reaction_delay=p[:, 3:])
        assert np.all(vals >= low[None, :] - 1e-12)


def test_axis_free_against_the_point_count() -> None:
    """No root on jℝ is proven for a box of stable members; a box whose θ_r range crosses the
    stability boundary of (1.0, 0.5) at τ = 0.1, T* = 1.1 is never proven free."""
    from stringstab.certify.quasipolynomial import count_unstable_roots

    one = np.array
    rc = count_unstable_roots(one([1.0, 1.0]), one([0.5, 0.5]), 0.1, 1.1, one([0.2, 1.5]))
    assert rc.status.tolist() == [0, 1]  # stable at θ_r = 0.2, unstable at 1.5
    a = box_axis.axis_free(one([1.0]), one([0.5]), check_box(0.1, 0.0, 1.1, "0.2:1.5"))
    assert a.free.tolist() == [False]
    a = box_axis.axis_free(one([1.0]), one([0.5]), check_box("0.08:0.12", 0.0, "1.0:1.2", "0.1:0.3"))
    assert a.free.tolist() == [True]


def test_theta_zero_box_runs_todays_code() -> None:
    """A box with θ_r = (0, 0) goes to robust_continuous: the same numbers (a dispatch check,
    an identity by construction), the plain batch type and no θ_r column."""
    kx, kv, ka = np.array([1.2, 0.9]), np.array([0.5, -0.5]), np.array([0.6, 1.1])
    box = check_box("0.1:0.3", "0.1:0.3", 1.1)
    b = robust.certify_kernel(kx, kv, ka, box, None)
    assert type(b) is robust.RobustCertificateBatch
    assert "reaction_delay" not in b.columns()["witness"]
    r = robust_continuous.certify_box_continuous(kx, kv, ka, box, n_grid=64, max_rounds=30,
                                                 max_intervals=1024)
    np.testing.assert_array_equal(b.margin, r["margin"])
    np.testing.assert_array_equal(b.witness_omega, r["omega"])


def test_refusals() -> None:
    with pytest.raises(StringStabError, match=r"continuous time only .*with sample_time=0\.1"):
        ss.certify(1.2, 0.5, 0.6, tau="0.1:0.2", delta=0.2, headway=1.1,
                   reaction_delay="0.1:0.2", sample_time=0.1)
    with pytest.raises(StringStabError, match="lo <= hi"):
        ss.certify(1.2, 0.5, 0.6, tau=0.1, delta=0.2, headway=1.1, reaction_delay="0.3:0.1")


def test_columns_carry_the_witness_reaction_delay() -> None:
    b = ss.certify_batch([1.2], [0.5], [0.6], tau=0.15, delta=0.2, headway=1.1,
                         reaction_delay="0.05:0.3")
    cols = b.columns()
    assert cols["witness"]["reaction_delay"].tolist() == [b[0].witness_reaction_delay]
    assert cols["box"]["reaction_delay_lo"].tolist() == [0.05]
    assert any(c.header == "θ_r" for c in b.table_columns())


def test_small_seeded_run_of_the_independent_check(check: Any) -> None:
    out = check.run(40, seed=11, verbose=False)
    c = out["counts"]
    assert c["unsound"] == 0 and c["false_witness"] == 0
    assert c["certified"] >= 5 and c["not_certified"] >= 5  # both kinds were checked


def test_region_maps_a_box_with_theta(tmp_path: Path) -> None:
    """``region`` over a box with θ_r draws the box certificate's verdicts (it dropped θ_r to 0
    before the box certificate existed, had the refusal been lifted): the map equals
    certify_batch at the grid's triples."""
    from stringstab.cli import main

    out = tmp_path / "reg"
    main(["region", "--fix", "k_a=0.5", "--tau", "0.1:0.2", "--reaction-delay", "0.1", "--n", "7",
          "--out", str(out)])
    d = np.load(out / "region.npz")
    kx, kv = np.meshgrid(d["axis_k_x"], d["axis_k_v"], indexing="ij")
    b = ss.certify_batch(kx.ravel(), kv.ravel(), 0.5, tau=(0.1, 0.2), delta=0.2, headway=1.1,
                         reaction_delay=0.1)
    codes = np.array([["certified", "not_certified", "inconclusive"].index(v) for v in b.verdict])
    assert np.array_equal(np.asarray(d["verdict_exact"]).ravel(), codes)
    assert np.array_equal(np.asarray(d["hurwitz"]).ravel(), b.stable)
    assert 0 < codes.tolist().count(0) < codes.size  # some certified, some not


def test_the_box_tails_hold_for_every_member() -> None:
    """Beyond box_margin_tail every member's g_θ > 0, and beyond box_tail every member's
    |τs³ + s²| > |cs + k_x| on jℝ (random members, frequencies up to 50 Ω)."""
    from stringstab.certify.margin_reaction import g

    rng = np.random.default_rng(5)
    box = check_box("0.05:0.3", "0:0.4", "0.5:2", "0:0.5")
    lo, hi = np.array([0.05, 0.0, 0.5, 0.0]), np.array([0.3, 0.4, 2.0, 0.5])
    for _ in range(10):
        k = rng.uniform([-1.0, -2.0, -1.5], [2.0, 2.0, 1.5])
        if abs(k[0]) < 1e-3:
            continue
        Om = robust_reaction.box_margin_tail(*(np.array([v]) for v in k), box)[0]
        Od = box_axis.box_tail(np.array([k[0]]), np.array([k[1]]), box)[0]
        p = lo + (hi - lo) * rng.uniform(size=(100, 4))
        w = np.linspace(Om, 50 * Om, 400)[None, :]
        assert np.all(g(w, *k, tau=p[:, :1], delta=p[:, 1:2], headway=p[:, 2:3],
                        reaction_delay=p[:, 3:]) > 0)
        w = np.linspace(Od, 50 * Od, 400)[None, :]
        c = k[1] + p[:, 2:3] * k[0]
        assert np.all(np.abs(p[:, :1] * (1j * w) ** 3 + (1j * w) ** 2) > np.abs(c * 1j * w + k[0]))
