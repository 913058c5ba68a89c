"""The results of the certificate with a reaction delay θ_r > 0: rows, columns and reasons.

A :class:`ReactionCertificateBatch` is a :class:`~stringstab.certify.continuous.CertificateBatch`
(same columns, same meaning) with three more: ``reaction_delay`` (θ_r, s; only ever in a batch
with θ_r > 0, so a θ_r = 0 row is today's row), ``unstable_roots`` (the proven number of roots
of the quasi-polynomial denominator in Re s > 0; NaN where not counted) and ``reason`` (the
verdict in words: which proof failed or succeeded, with its witness).  Two columns change
meaning for θ_r > 0 and say so in docs/certify.md: ``hurwitz`` is "internally stable, proven"
(the quasi-polynomial has no root in Re s ≥ 0; it is no Hurwitz test), and ``hurwitz_margin``
is an *estimate* of −Re of the rightmost root (:mod:`stringstab.certify.rightmost`), NaN where
its sign would disagree with ``hurwitz``.  ``taylor_derived`` is Proposition 1 on the Ψ *with*
θ_r; ``taylor_printed`` stays the paper's (θ_r = 0).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np
import numpy.typing as npt

from ..io import TableColumn
from .continuous import TABLE_COLUMNS, Certificate, CertificateBatch
from .verdicts import CERTIFIED, NOT_CERTIFIED, num

__all__ = ["REACTION_TABLE_COLUMNS", "ReactionCertificate", "ReactionCertificateBatch", "reasons"]

Array = npt.NDArray[np.float64]


def _table() -> list[TableColumn]:
    cols = list(TABLE_COLUMNS)
    at = next(i for i, c in enumerate(cols) if c.key == "hurwitz") + 1
    cols.insert(at, TableColumn("roots Re>0", "unstable_roots", "%.0f", missing="?"))
    cols.append(TableColumn("reason", "reason", "%s"))
    return cols


#: The human table with θ_r > 0: the continuous table, the root count and the reason.
REACTION_TABLE_COLUMNS: list[TableColumn] = _table()


@dataclass(frozen=True)
class ReactionCertificate(Certificate):
    """The certificate of one triple with θ_r > 0 (:class:`Certificate` and three fields).

    Attributes
    ----------
    unstable_roots : float
        Roots of D(s) = P(s) + e^{−θ_r s}Q(s) in Re s > 0, proven (NaN: not counted).
    reason : str
        The verdict in words, with its witness.
    """

    unstable_roots: float = float("nan")
    reason: str = ""

    def as_dict(self) -> dict[str, Any]:
        """The JSON row: :meth:`Certificate.as_dict` with ``reaction_delay``, the count, the reason."""
        out: dict[str, Any] = {}
        for k, v in super().as_dict().items():
            out[k] = v
            if k == "k_a":
                out["reaction_delay"] = self.params.reaction_delay
            elif k == "hurwitz_margin":
                out["unstable_roots"] = num(self.unstable_roots)
            elif k == "verdict":
                out["reason"] = self.reason
        return out


@dataclass(frozen=True)
class ReactionCertificateBatch(CertificateBatch):
    """Certificates with θ_r > 0 of many triples (see :class:`ReactionCertificate`)."""

    TABLE: ClassVar[Sequence[TableColumn]] = REACTION_TABLE_COLUMNS

    unstable_roots: Array = field(default_factory=lambda: np.zeros(0))
    reason: npt.NDArray[np.str_] = field(default_factory=lambda: np.zeros(0, dtype=str))

    def __getitem__(self, i: int) -> ReactionCertificate:
        c = super().__getitem__(i)
        values = {k: getattr(c, k) for k in c.__dataclass_fields__}
        return ReactionCertificate(**values, unstable_roots=float(self.unstable_roots[i]),
                                   reason=str(self.reason[i]))

    def columns(self) -> dict[str, Any]:
        """:meth:`CertificateBatch.columns` with ``reaction_delay``, ``unstable_roots``, ``reason``.

        Returns
        -------
        dict
            The columns in the order of :meth:`ReactionCertificate.as_dict`.
        """
        out: dict[str, Any] = {}
        for k, v in super().columns().items():
            out[k] = v
            if k == "k_a":
                out["reaction_delay"] = np.full(len(self), self.params.reaction_delay)
            elif k == "hurwitz_margin":
                out["unstable_roots"] = self.unstable_roots
            elif k == "verdict":
                out["reason"] = self.reason
        return out


def _g(x: float) -> str:
    return f"{x:.3g}"


def reasons(verdict: npt.NDArray[np.int8], unstable: npt.NDArray[np.bool_],
            violated: npt.NDArray[np.bool_], roots: Array, real_root: Array, min_abs: Array,
            min_omega: Array, margin: Array, witness: Array) -> npt.NDArray[np.str_]:
    """The verdict of each row in words, with the witness that decided it.

    Parameters
    ----------
    verdict : ndarray of int8
        Verdict codes.
    unstable, violated : ndarray of bool
        Proven: roots in Re s ≥ 0; g_θ < −slack somewhere (|Γ(jω)| > 1).
    roots : ndarray
        The number of roots in Re s > 0 (NaN: not counted).
    real_root : ndarray
        A real root σ > 0 where k_x < 0 (NaN elsewhere).
    min_abs, min_omega : ndarray
        The smallest |D(jω)| met by the root count, and where (rad/s).
    margin, witness : ndarray
        The smallest g_θ found by the branch and bound, and where (rad/s).

    Returns
    -------
    ndarray of str
        ``"stable (no root in Re s ≥ 0) and |Γ(jω)| ≤ 1 at every ω"``,
        ``"unstable: 2 roots in Re s > 0"``, ``"|Γ(jω)| > 1 at ω = 1.7 rad/s (g_θ = -0.3)"``,
        ``"undecided: ..."`` (with the smallest |D(jω)| or g_θ met: the distance to the boundary).

    Examples
    --------
    >>> reasons(np.array([1], np.int8), np.array([True]), np.array([False]), np.array([2.0]),
    ...         np.array([np.nan]), np.array([0.5]), np.array([1.0]), np.array([0.1]),
    ...         np.array([0.0])).tolist()
    ['unstable: 2 roots in Re s > 0']
    """
    out = []
    for i in range(verdict.size):
        parts = []
        if verdict[i] == CERTIFIED:
            out.append("stable (no root in Re s ≥ 0) and |Γ(jω)| ≤ 1 at every ω")
            continue
        if unstable[i]:
            if np.isfinite(roots[i]):
                k = int(roots[i])
                parts.append(f"unstable: {k} root{'s' if k != 1 else ''} in Re s > 0")
            elif np.isfinite(real_root[i]):
                parts.append(f"unstable: a real root at s = {_g(real_root[i])} (k_x < 0)")
            else:
                parts.append("unstable: a root at s = 0 (k_x = 0)")
        if violated[i] and witness[i] > 0:
            parts.append(f"|Γ(jω)| > 1 at ω = {_g(witness[i])} rad/s (g_θ = {_g(margin[i])})")
        elif violated[i]:  # g_θ(0) = Ψ3 < 0: |Γ(jω)|² ≈ 1 − Ψ3ω²/k_x² > 1 for small ω
            parts.append(f"|Γ(jω)| > 1 near ω = 0 (Ψ3 = g_θ(0) = {_g(margin[i])})")
        if verdict[i] != NOT_CERTIFIED:
            if not np.isfinite(roots[i]):
                parts.append(f"undecided: stability, |D(jω)| down to {_g(min_abs[i])} at "
                             f"ω = {_g(min_omega[i])} rad/s")
            elif roots[i] == 0:
                parts.append(f"undecided: |Γ| ≤ 1, g_θ down to {_g(margin[i])} at "
                             f"ω = {_g(witness[i])} rad/s")
        out.append("; ".join(parts))
    return np.array(out, dtype=str)
