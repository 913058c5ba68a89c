"""The Padé cross-check: python-control's view of Γ(s), never a verdict.

The exact delay e^{−δs} is replaced by a Padé approximant (``control.pade``), stability is
checked on the poles of that rational model, and ``control.norm(·, 'inf')`` gives its H∞
norm.  :func:`certify_pade` answers for one triple; :func:`cross_check` adds those numbers
to a continuous batch (``method="pade"`` of :func:`stringstab.certify.certify_batch`) and
warns where they disagree with the exact verdict, which is always the one reported.
python-control is imported only here, on first use.
"""

from __future__ import annotations

import dataclasses
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..derive import generated as gen
from ..params import Params, as_gains
from .continuous import CertificateBatch
from .verdicts import Verdict, num

__all__ = ["PadeResult", "certify_pade", "cross_check"]


@dataclass(frozen=True)
class PadeResult:
    """python-control's view: Padé(n) delay, own stability check, then ``norm(·, 'inf')``."""

    order: int
    stable: bool
    hinf: float
    linf: float
    verdict: str

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        return {"order": self.order, "stable": self.stable, "hinf": num(self.hinf),
                "linf": num(self.linf), "verdict": self.verdict}


def certify_pade(
    k_x: float, k_v: float, k_a: float, *, tau: float, delta: float, headway: float,
    order: int = 5, tol: float = 1e-6, norm_tol: float = 1e-10,
) -> PadeResult:
    """The python-control cross-check of one triple.

    The delay is replaced by ``control.pade(delta, order)``; stability is
    checked on the poles *before* ``control.norm(sys, 'inf')`` is trusted
    (that function returns the L∞ norm and never checks stability).  The
    verdict is ``"certified"`` when stable and the norm ≤ 1 + ``tol``; it is an
    approximation (Padé) and a cross-check only.  ``norm_tol`` is passed to
    ``control.norm`` (its default, 1e-6, cannot resolve sup |Γ| = 1).

    Parameters
    ----------
    k_x, k_v, k_a : float
        The gains.
    tau, delta, headway : float
        Actuator lag τ, delay δ, desired headway T*, s.
    order : int
        Order of the Padé approximant of e^{−δs}.
    tol : float
        Slack on the norm for the verdict.
    norm_tol : float
        Tolerance passed to ``control.norm``.

    Returns
    -------
    PadeResult
        ``stable``, ``hinf`` (the Padé model's H∞ norm) and ``verdict``.

    Examples
    --------
    >>> r = certify_pade(1.5, 0.3, -0.1, tau=0.1, delta=0.2, headway=1.1)
    >>> r.stable, r.verdict
    (True, 'certified')
    """
    p = Params(tau, delta, headway)
    kx, kv, ka = (float(v) for v in as_gains(k_x, k_v, k_a))
    return _pade(kx, kv, ka, p, order, tol, norm_tol)


def _pade(kx: float, kv: float, ka: float, p: Params, order: int, tol: float = 1e-6,
          norm_tol: float = 1e-10) -> PadeResult:
    """:func:`certify_pade` of checked inputs."""
    import control

    if p.delta > 0:
        num_d, den_d = control.pade(p.delta, order)
        delay = control.tf(num_d, den_d)
    else:
        delay = control.tf([1.0], [1.0])
    # N(s) = n0(s) + n1(s) e^{-δs} and D(s), generated from the derivation
    d_co = [float(c) for c in gen.denominator_coefficients(kx, kv, ka, p.tau, p.delta, p.headway)]
    n_co = [float(c) for c in gen.numerator_coefficients(kx, kv, ka, p.tau, p.delta, p.headway)]
    n0, n1 = n_co[:gen.NUMERATOR_SPLIT], n_co[gen.NUMERATOR_SPLIT:]
    den = control.tf(d_co, [1.0])
    sys = (control.tf(n0, [1.0]) + control.tf(n1, [1.0]) * delay) / den
    poles = np.concatenate([np.roots(d_co), np.asarray(control.poles(delay))])
    stable = bool(np.all(poles.real < 0))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            linf = float(control.norm(sys, "inf", tol=norm_tol))
        except Exception:  # python-control raises on poles on the imaginary axis
            linf = float("inf")
    hinf = linf if stable else float("inf")
    verdict = Verdict.CERTIFIED.value if stable and hinf <= 1.0 + tol else Verdict.NOT_CERTIFIED.value
    return PadeResult(order, stable, hinf, linf, verdict)


def cross_check(batch: CertificateBatch, order: int, *, stacklevel: int = 3) -> CertificateBatch:
    """The batch with python-control's Padé numbers per row, warning where they disagree.

    Inputs already checked by :func:`stringstab.certify.certify_batch` (the way in asks for
    it with ``method="pade"``).  A row *agrees* when both verdicts are equal or the exact one
    is inconclusive; the verdicts reported stay the exact ones.

    Parameters
    ----------
    batch : CertificateBatch
        The exact continuous certificates (point parameters).
    order : int
        Padé order of the delay.
    stacklevel : int
        Passed to :func:`warnings.warn` (3: the caller of ``certify_batch``).

    Returns
    -------
    CertificateBatch
        ``batch`` with ``method="pade"`` and one :meth:`PadeResult.as_dict` row (plus
        ``agrees``) per triple in ``pade``.
    """
    p = batch.params
    kx, kv, ka, vnames, hinf = batch.k_x, batch.k_v, batch.k_a, batch.verdict, batch.sup_gain
    n = len(kx)
    rows: list[dict[str, Any]] = []
    disagree = []
    for i in range(n):
        pr = _pade(float(kx[i]), float(kv[i]), float(ka[i]), p, order)
        row = pr.as_dict()
        row["agrees"] = pr.verdict == vnames[i] or vnames[i] == Verdict.INCONCLUSIVE.value
        if not row["agrees"]:
            disagree.append(
                f"K=({kx[i]:g}, {kv[i]:g}, {ka[i]:g}): exact {vnames[i]} (sup {hinf[i]:.9g}), "
                f"Padé {pr.verdict} (norm {pr.hinf:.9g})"
            )
        rows.append(row)
    if disagree:
        more = f" and {len(disagree) - 3} more" if len(disagree) > 3 else ""
        warnings.warn(
            f"Padé({order}) cross-check disagrees with the exact certificate on "
            f"{len(disagree)} of {n} triples: " + "; ".join(disagree[:3]) + more,
            stacklevel=stacklevel,
        )
    return dataclasses.replace(batch, method="pade", pade=rows)
