"""The names and codes of a region map: the gains, the methods, the verdict labels, the classes.

Shared by :mod:`~stringstab.regions.result` (:class:`~stringstab.regions.RegionMap`) and
:mod:`~stringstab.regions.storage` (its files); re-exported by both packages' public paths
(``stringstab.regions.GAIN_NAMES``, ``stringstab.regions.result.VERDICT_LABELS``, ...).
"""

from __future__ import annotations

import numpy as np

from ..certify.verdicts import CERTIFIED, NOT_CERTIFIED, VERDICTS, Verdict

__all__ = [
    "CERTIFICATE_METHODS",
    "CONTINUOUS",
    "EXACT_CLASSES",
    "GAIN_NAMES",
    "METHODS",
    "STABLE",
    "TYPE_CLASSES",
    "TYPE_TO_CLASS",
    "UNSTABLE",
    "VERDICT_LABELS",
]

#: The gains, in the order of K = [k_x, k_v, k_a] (IDL eq 4).
GAIN_NAMES: tuple[str, str, str] = ("k_x", "k_v", "k_a")
#: The methods a map of the continuous loop at one τ, δ, T* can evaluate (the default set).
METHODS: tuple[str, str, str] = ("exact", "taylor", "printed")
#: The comparison method of a sampled-data map: the continuous-time certificate at the same
#: parameters (or box), beside ``exact`` (the sampled certificate).
CONTINUOUS = "continuous"
#: Every method's per-point codes are the verdict codes (:mod:`stringstab.certify.verdicts`):
#: 0 says string stable, 1 says not, 2 cannot tell.
STABLE, UNSTABLE = CERTIFIED, NOT_CERTIFIED
#: The labels of those codes for a certificate: the verdicts themselves.
_CERTIFICATE_LABELS: tuple[str, str, str] = (VERDICTS[0].value, VERDICTS[1].value,
                                             VERDICTS[2].value)
#: The labels of those codes for the Taylor methods (derived and printed Ψ, IDL Proposition 1).
#: They say "stable" / "unstable", never "certified": a test on a Taylor approximation of the
#: delay is not a certificate (it can call unstable gains stable), so its answer must not read
#: as the certificate's.  Code 2 is never produced by them; its label is kept for a uniform table.
_APPROXIMATION_LABELS: tuple[str, str, str] = ("stable", "unstable", Verdict.INCONCLUSIVE.value)
#: Labels of the codes 0, 1, 2 per method.
VERDICT_LABELS: dict[str, tuple[str, str, str]] = {
    "exact": _CERTIFICATE_LABELS,
    "taylor": _APPROXIMATION_LABELS,
    "printed": _APPROXIMATION_LABELS,
    CONTINUOUS: _CERTIFICATE_LABELS,
}
#: Methods decided by a certificate (tri-state verdicts, the classes of :data:`EXACT_CLASSES`).
CERTIFICATE_METHODS: tuple[str, str] = ("exact", CONTINUOUS)
#: Classes of the ``taylor`` and ``printed`` class maps, by code 0-4.
TYPE_CLASSES: tuple[str, ...] = (
    "not internally stable", "type III", "type IV", "type I", "type II",
)
#: Classes of the ``exact`` class map, by code 0-3: not internally stable, then the verdicts.
EXACT_CLASSES: tuple[str, ...] = (
    "not internally stable", Verdict.NOT_CERTIFIED.words, Verdict.INCONCLUSIVE.words,
    Verdict.CERTIFIED.words,
)
#: stability_type code (1 = I, ..., 4 = IV) -> :data:`TYPE_CLASSES` code.
TYPE_TO_CLASS = np.array([0, 3, 4, 1, 2], dtype=np.int8)
