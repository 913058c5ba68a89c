"""The one way in (stringstab.certify.api): the loop decided once, the inputs checked once.

The counts are of calls into the validators of :mod:`stringstab.params` (read with a
profiler, so no code is patched); before the way in checked once, ``certify_batch`` with a
sample time checked τ, δ, T* twice, H twice and the gains twice.
"""

from __future__ import annotations

import collections
import contextlib
import io
import sys

import numpy as np
import pytest

import stringstab
from stringstab import params
from stringstab.certify import continuous, robust, sampled
from stringstab.certify.api import Loop, certify_batch
from stringstab.certify.verdicts import BatchResult
from stringstab.cli import main
from stringstab.errors import StringStabError
from stringstab.io.results import TableColumn

P = dict(tau=0.1, delta=0.2, headway=1.1)
K = np.random.default_rng(20).uniform(-1, 2, (40, 3))
VALIDATORS = {"check_params", "sample_time", "as_gains", "check_box", "parameter_model"}


def _validations(fn) -> collections.Counter[str]:
    """Calls of the validators of stringstab/params/ made by ``fn()``, by name."""
    seen: collections.Counter[str] = collections.Counter()
    target = {params.points.__file__, params.intervals.__file__}

    def prof(frame, event, arg):
        if event == "call" and frame.f_code.co_filename in target and frame.f_code.co_name in VALIDATORS:
            seen[frame.f_code.co_name] += 1

    # import the lazily loaded certificates first, so only the certificate's own calls count
    assert sampled and robust
    sys.setprofile(prof)
    try:
        fn()
    finally:
        sys.setprofile(None)
    return seen


@pytest.mark.parametrize("kw, kind, batch_type", [
    ({}, "continuous", continuous.CertificateBatch),
    ({"sample_time": 0.1}, "sampled", sampled.SampledCertificateBatch),
    ({"tau": (0.1, 0.2)}, "robust", robust.RobustCertificateBatch),
    ({"tau": "0.1:0.2", "sample_time": 0.1}, "robust", robust.RobustCertificateBatch),
    ({"tau": (0.1, 0.1)}, "continuous", continuous.CertificateBatch),  # a point interval
])
def test_the_loop_kind_is_decided_once_and_picks_the_certificate(kw, kind, batch_type):
    args = {**P, **kw}
    loop = Loop.of(args["tau"], args["delta"], args["headway"], args.get("sample_time"))
    assert loop.kind == kind
    b = stringstab.certify_batch(*K[:5].T, **args)
    assert type(b) is batch_type
    assert np.array_equal(loop.certify_batch(*K[:5].T).verdict, b.verdict)


@pytest.mark.parametrize("kw, expected", [
    ({}, {"parameter_model": 1, "check_params": 1, "as_gains": 1}),
    ({"sample_time": 0.1}, {"parameter_model": 1, "check_params": 1, "sample_time": 1, "as_gains": 1}),
    ({"tau": (0.1, 0.2)}, {"parameter_model": 1, "check_box": 1, "as_gains": 1}),
])
def test_certify_batch_and_check_validate_once(kw, expected):
    args = {**P, **kw}
    assert _validations(lambda: stringstab.certify_batch(*K.T, **args)) == expected
    assert _validations(lambda: stringstab.check(*K.T, **args)) == expected
    assert _validations(lambda: stringstab.certify(*K[0], **args)) == expected


def test_the_command_line_checks_the_sampled_loop_once():
    # the CLI checks τ, δ, T* and H with its flags' names; the library checks the gains
    def run():
        with contextlib.redirect_stdout(io.StringIO()):
            assert main(["certify", "1.2,0.5,0.6", "--sample-time", "0.1"]) == 0

    assert _validations(run) == {"check_params": 1, "as_gains": 1}


def test_the_count_can_fail():
    # the way in, given the values of a loop it has already checked, checks them again
    def twice():
        loop = Loop.of(**P, sample_time=0.1)
        certify_batch(*K.T, tau=loop.model.tau, delta=loop.model.delta,
                      headway=loop.model.headway, sample_time=0.1)

    assert _validations(twice)["check_params"] > 1


def test_the_kernels_give_the_way_ins_results():
    kx, kv, ka = (np.ascontiguousarray(c) for c in K.T)
    p = params.Params(**P)
    a = sampled.certify_kernel(kx, kv, ka, p, 0.1, 0.1)
    b = certify_batch(kx, kv, ka, sample_time=0.1, **P)
    ca, cb = dict(_flat(a.columns())), dict(_flat(b.columns()))
    assert ca.keys() == cb.keys()
    for k, v in cb.items():
        np.testing.assert_array_equal(ca[k], v, err_msg=k)
    box = params.Box((0.1, 0.2), (0.2, 0.2), (1.1, 1.1))
    r = robust.certify_kernel(kx[:10], kv[:10], ka[:10], box, None)
    r2 = certify_batch(kx[:10], kv[:10], ka[:10], tau=(0.1, 0.2), delta=0.2, headway=1.1)
    assert np.array_equal(r.verdict, r2.verdict) and np.array_equal(r.sup_gain, r2.sup_gain)


def _flat(d, pre=""):
    for k, v in d.items():
        yield from (_flat(v, f"{pre}{k}.") if isinstance(v, dict) else [(f"{pre}{k}", v)])


@pytest.mark.parametrize("kw", [{}, {"sample_time": 0.1}, {"tau": (0.1, 0.2)}])
def test_each_batch_names_its_table_columns(kw):
    b = stringstab.certify_batch(*K[:5].T, **{**P, **kw})
    cols = b.table_columns()
    assert cols and all(isinstance(c, TableColumn) for c in cols)

    keys = {k for k, _ in _flat(b.columns())}
    optional = {"t", "vehicle", "pade.verdict", "pade.hinf"}  # input's time/vehicle, --method pade
    assert {c.key for c in cols} - optional <= keys
    assert cols is not b.table_columns()  # a copy: a caller cannot change the type's columns


def test_a_batch_type_without_table_columns_says_so():
    with pytest.raises(NotImplementedError, match="names no table columns"):
        BatchResult.table_columns()


@pytest.mark.parametrize("kw, got", [({"sample_time": 0.1}, "got sample_time=0.1"),
                                     ({"tau": "0.1:0.2"}, "got a parameter box")])
def test_the_pade_refusal_is_the_library_s_on_both_paths(capsys, kw, got):
    with pytest.raises(StringStabError, match=f"method='pade' .* continuous loop .*; {got}$"):
        stringstab.certify_batch([1.0], [1.0], [1.0], **{**P, **kw}, method="pade")
    flags = ["--sample-time", "0.1"] if "sample_time" in kw else ["--tau", "0.1:0.2"]
    assert main(["certify", "1,1,1", "--method", "pade", *flags]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("stringstab certify: error: method='pade'")
    assert err[0].endswith(got)


def test_a_loop_built_from_checked_values_refuses_what_no_certificate_answers():
    with pytest.raises(StringStabError, match=r"tau_prev .* sampled loop"):
        Loop(params.Params(**P), None, tau_prev=0.2)
    with pytest.raises(StringStabError, match="method must be 'exact' or 'pade'"):
        Loop(params.Params(**P), method="taylor")
    with pytest.raises(StringStabError, match=r"tau_prev .* must be a finite number > 0"):
        Loop.of(**P, sample_time=0.1, tau_prev=-0.1)
    assert Loop.of(**P, sample_time=0.1, tau_prev="0.2").predecessor_lag == 0.2
    assert Loop.of(**P, sample_time=0.1).predecessor_lag == 0.1
