"""stringstab: is this car-following controller string stable?

Symbolic derivation of Γ(s), Ψ1-Ψ3 and Λ (:mod:`stringstab.symbolic`), the
printed formulas of the IDL paper and their errata (:mod:`stringstab.printed`,
:mod:`stringstab.errata`), exact delay-aware certificates, stability-region
maps, gain repair, a platoon simulator and a compact policy trainer.
"""

from __future__ import annotations

__version__ = "0.1.0"

from .errata import Erratum, errata
from .errors import StringStabError
from .params import DEFAULT_DELTA, DEFAULT_HEADWAY, DEFAULT_TAU, Params

__all__ = [
    "DEFAULT_DELTA",
    "DEFAULT_HEADWAY",
    "DEFAULT_TAU",
    "Erratum",
    "Params",
    "StringStabError",
    "__version__",
    "errata",
]
