"""`stringstab derive` end to end."""

import json

import pytest
import sympy as sp

from stringstab.cli import main
from stringstab.derive import symbolic as S

KEYS = ["gamma", "gamma_numerator", "gamma_denominator", "psi1", "psi2", "psi3", "lambda",
        "grad_psi2", "grad_psi3", "hurwitz"]
LOCALS = {str(x): x for x in (*S.GAINS, *S.PARAMS, S.s, S.omega)}


def _json(capsys, *args):
    assert main(["derive", "--format", "json", *args]) == 0
    return json.loads(capsys.readouterr().out)


def test_json_keys_and_parsable(capsys):
    doc = _json(capsys, "--errata")
    for k in KEYS:
        assert k in doc
    exprs = S.derive_all()
    for k in KEYS:
        vals = doc[k] if isinstance(doc[k], list) else [doc[k]]
        ref = exprs[k] if isinstance(exprs[k], list) else [exprs[k]]
        assert len(vals) == len(ref)
        for v, r in zip(vals, ref):
            assert sp.simplify(sp.sympify(v, locals=LOCALS) - r) == 0, k
    for e in doc["errata"]:
        assert set(e) >= {"equation", "printed", "derived", "difference", "matches"}
    assert {e["equation"] for e in doc["errata"] if not e["matches"]} >= {"11", "12", "13", "25"}


def test_substitute(capsys):
    doc = _json(capsys, "--substitute", "tau=0.1,delta=0.2,headway=1.1")
    psi3 = sp.sympify(doc["psi3"], locals=LOCALS)
    assert psi3.free_symbols == {S.k_x, S.k_v, S.k_a}
    assert doc["hurwitz"] == ["k_x", "k_v + k_x"]


def test_text_and_latex(capsys):
    assert main(["derive", "--errata"]) == 0
    out = capsys.readouterr().out
    assert "Ψ1 = " in out and "[ERR] eq 13" in out
    assert main(["derive", "--format", "latex"]) == 0
    out = capsys.readouterr().out
    assert r"\begin{align*}" in out and r"\Psi_2 &=" in out


@pytest.mark.parametrize("bad, msg", [
    (["--substitute", "tau=-1"], "tau"),
    (["--substitute", "zeta=1"], "unknown symbol"),
    (["--delay-order", "x"], "delay-order"),
])
def test_bad_input_exit_2(capsys, bad, msg):
    assert main(["derive", *bad]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert msg in captured.err
