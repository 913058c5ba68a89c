"""stringstab: is this car-following controller string stable?

Symbolic derivation of Γ(s), Ψ1-Ψ3 and Λ (:mod:`stringstab.symbolic`), the
printed formulas of the IDL paper and their errata (:mod:`stringstab.printed`,
:mod:`stringstab.errata`), exact delay-aware certificates, stability-region
maps, gain repair, a platoon simulator and a compact policy trainer.
"""

from __future__ import annotations

from typing import Any

from ._version import __version__
from .certificate import Certificate, CertificateBatch, certify, certify_batch, certify_pade, check
from .criteria import hurwitz, stability_type, taylor_criteria
from .errors import StringStabError
from .frequency import gain, gamma_jw, margin_g
from .io.gains import GainTable, parse_triple, read_gains
from .params import DEFAULT_DELTA, DEFAULT_HEADWAY, DEFAULT_TAU, Box, Params
from .verdicts import VERDICTS, Check

# Importing stringstab (and certifying) loads NumPy only: no SymPy, matplotlib, CasADi,
# python-control or gymnasium (tests/test_house.py checks it), and the sampled-data and
# robust certificates (stringstab.sampled, stringstab.robust) only when certify, certify_batch
# or check is asked for a sample time or a parameter interval.  The errata (SymPy) are
# loaded on first use of their names below; the simulator (stringstab.traffic,
# stringstab.metrics), the region maps (stringstab.regions, stringstab.plots) and the
# gain repair (stringstab.tuning) are imported on demand.
_LAZY = {"Erratum": "errata", "errata": "errata"}


def __getattr__(name: str) -> Any:
    """The names of :data:`_LAZY`, imported on first use (they pull in SymPy)."""
    if name in _LAZY:
        import importlib

        value = getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

__all__ = [
    "DEFAULT_DELTA",
    "DEFAULT_HEADWAY",
    "DEFAULT_TAU",
    "VERDICTS",
    "Box",
    "Certificate",
    "CertificateBatch",
    "Check",
    "Erratum",
    "GainTable",
    "Params",
    "StringStabError",
    "__version__",
    "certify",
    "certify_batch",
    "certify_pade",
    "check",
    "errata",
    "gain",
    "gamma_jw",
    "hurwitz",
    "margin_g",
    "parse_triple",
    "read_gains",
    "stability_type",
    "taylor_criteria",
]
