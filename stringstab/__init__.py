"""stringstab: exact, delay-aware string-stability analysis of car-following controllers.

The package is laid out in layers, each a subpackage whose ``__init__`` says what lives there:

* :mod:`stringstab.derive` — everything SymPy: the derivation of Γ(s), Ψ1–Ψ3 and Λ, the
  printed formulas of the papers and their errata, and the numeric code generated from them;
* :mod:`stringstab.certify` — the certificates (continuous, sampled-data, robust) behind one
  way in: :func:`certify`, :func:`check`, :func:`certify_batch`;
* :mod:`stringstab.regions`, :mod:`stringstab.tuning` — stability-region maps and gain repair;
* :mod:`stringstab.traffic`, :mod:`stringstab.hcfs`, :mod:`stringstab.rl` — the platoon
  simulator and its metrics, the HCFS switch, the TD3/DDPG trainer;
* :mod:`stringstab.identify`, :mod:`stringstab.sumo`, :mod:`stringstab.sweep` — recorded
  platoons, SUMO, Dask sweeps;
* :mod:`stringstab.io`, :mod:`stringstab.plots`, :mod:`stringstab.report`,
  :mod:`stringstab.cli` — files, figures, reports and the command line.

The root holds this façade and the shared basics: :mod:`~stringstab.params` (the model's
parameters), :mod:`~stringstab.ranges` (their sensible ranges), :mod:`~stringstab.constants`,
:mod:`~stringstab.errors`, :mod:`~stringstab.progress` and the version.
"""

from __future__ import annotations

from typing import Any

from ._version import __version__
from .certify import (
    Certificate,
    CertificateBatch,
    certify,
    certify_batch,
    certify_pade,
    check,
)
from .certify.criteria import hurwitz, stability_type, taylor_criteria
from .certify.frequency import gain, gamma_jw, margin_g
from .certify.verdicts import VERDICTS, Check
from .errors import StringStabError
from .io.gain_table import GainTable
from .io.gains import parse_triple, read_gains
from .params import DEFAULT_DELTA, DEFAULT_HEADWAY, DEFAULT_TAU, Box, Params

# ``from .certify import certify`` binds the name ``certify`` of this package to the function
# (the way in), not to the subpackage stringstab.certify of the same name: reach the modules
# of that subpackage with ``from stringstab.certify import sampled`` (tests/house/test_house.py
# checks that the name stays the function).
#
# Importing stringstab (and certifying) loads NumPy only: no SymPy, matplotlib, CasADi,
# python-control or gymnasium (tests/house/test_house.py checks it), and the sampled-data and
# robust certificates (stringstab.certify.sampled, stringstab.certify.robust) only when
# certify, certify_batch or check is asked for a sample time or a parameter interval.  The
# errata (SymPy, stringstab.derive) are loaded on first use of their names below; the
# simulator (stringstab.traffic), the region maps (stringstab.regions, stringstab.plots) and
# the gain repair (stringstab.tuning) are imported on demand.
_LAZY = {"Erratum": "derive.errata", "errata": "derive.errata"}


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
