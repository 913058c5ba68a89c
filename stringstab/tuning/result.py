"""What a repair returns: :class:`TuneResult` for one triple, :class:`TuneResults` for many.

Each result type owns its records, columns and summary, which every command writes through
:mod:`stringstab.io`'s result writer.
"""

from __future__ import annotations

import time
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from ..certify import verdicts
from ..certify.continuous import Certificate
from ..io import TableColumn

__all__ = [
    "CERTIFIED_BY_CHECK",
    "TABLE_COLUMNS",
    "TuneResult",
    "TuneResults",
    "VerdictAndGain",
    "make_result",
    "triple",
    "wdist",
]

Array = npt.NDArray[np.float64]


@dataclass(frozen=True)
class TuneResult:
    """The outcome of repairing one gain triple.

    Attributes
    ----------
    method : str
        ``"region-growing"`` or ``"projection"``.
    k_in : tuple of float
        The input gains K0 = (k_x, k_v, k_a).
    k : tuple of float
        The output gains (K0 itself when unchanged or when no solution was found).
    certified : bool
        The output is certified string stable by the exact certificate.
    verdict : Verdict
        The exact certificate's verdict on the output (:class:`stringstab.certify.verdicts.Verdict`,
        a ``str``: ``"certified"``, ``"not_certified"`` or ``"inconclusive"``).
    status : str
        ``"unchanged"`` (the input was already certified), ``"repaired"`` (a new
        output was found and the exact certificate certifies it), ``"moved_not_certified"``
        (a new output was found, e.g. one the paper's Taylor test accepts, but the exact
        certificate does not certify it), ``"taylor_stable"`` (region growing only: the
        paper's Taylor test calls the input stable, so the paper's method does
        not act), ``"no_solution"`` (the paper's "No optimized solution found")
        or ``"failed"`` (projection only; never observed, see ``docs/tuning.md``).
    distance : float
        Weighted Euclidean distance ‖K − K0‖_W = sqrt(Σ w_i (K_i − K0_i)²).
    iterations : int
        Region growing: the index k of the last region R_k searched.
        Projection: the number of NLP solves (exchange iterations); an output of
        the Newton predictor counts as one solve (``details["predictor"]``).
    seconds : float
        Wall-clock time of the call.
    message : str
        A one-line human-readable account of what happened.
    sup_gain : float
        ‖Γ‖_{H∞} of the output (``inf`` when not internally stable).
    details : dict
        Method-specific numbers (grid points evaluated, frequencies used, ...).
    """

    method: str
    k_in: tuple[float, float, float]
    k: tuple[float, float, float]
    certified: bool
    verdict: verdicts.Verdict
    status: str
    distance: float
    iterations: int
    seconds: float
    message: str
    sup_gain: float = float("nan")
    details: dict[str, Any] = field(default_factory=dict)

    @property
    def changed(self) -> bool:
        """The output differs from the input."""
        return self.k != self.k_in

    def as_dict(self) -> dict[str, Any]:
        """A flat JSON-ready row (non-finite numbers are left to the writer)."""
        return {
            "method": self.method,
            "k_x_in": self.k_in[0],
            "k_v_in": self.k_in[1],
            "k_a_in": self.k_in[2],
            "k_x": self.k[0],
            "k_v": self.k[1],
            "k_a": self.k[2],
            "certified": self.certified,
            "verdict": self.verdict,
            "status": self.status,
            "distance": self.distance,
            "iterations": self.iterations,
            "time_ms": 1e3 * self.seconds,
            "sup_gain": self.sup_gain,
            "message": self.message,
        }


#: Columns of the human table of :class:`TuneResults` (``stringstab tune``), with units.
TABLE_COLUMNS: tuple[TableColumn, ...] = (
    TableColumn("t [s]", "t", "%.6g"),
    TableColumn("vehicle", "vehicle", "%d"),
    TableColumn("method", "method", "%s"),
    TableColumn("k_x_in [1/s²]", "k_x_in", "%.6g"),
    TableColumn("k_v_in [1/s]", "k_v_in", "%.6g"),
    TableColumn("k_a_in [-]", "k_a_in", "%.6g"),
    TableColumn("k_x [1/s²]", "k_x", "%.6g"),
    TableColumn("k_v [1/s]", "k_v", "%.6g"),
    TableColumn("k_a [-]", "k_a", "%.6g"),
    TableColumn(verdicts.Verdict.CERTIFIED.value, "certified", "%s"),
    TableColumn("status", "status", "%s"),
    TableColumn("distance", "distance", "%.4g"),
    TableColumn("iter", "iterations", "%d"),
    TableColumn("time [ms]", "time_ms", "%.3g"),
)


@dataclass(frozen=True)
class TuneResults:
    """The repairs of many triples (one :class:`TuneResult` per input and method).

    Attributes
    ----------
    results : tuple of TuneResult
        In input order, the methods of one input together.
    meta : dict of str to ndarray
        Per-result columns carried from the input (``t``, ``vehicle``), or empty.
    methods : tuple of str
        The methods run, in the order of their rows.
    """

    results: tuple[TuneResult, ...]
    meta: Mapping[str, npt.NDArray[Any]] = field(default_factory=dict)
    methods: tuple[str, ...] = ()

    def __len__(self) -> int:
        return len(self.results)

    def __iter__(self) -> Iterator[TuneResult]:
        return iter(self.results)

    def __getitem__(self, i: int) -> TuneResult:
        return self.results[i]

    @property
    def certified(self) -> npt.NDArray[np.bool_]:
        """Whether each output is certified by the exact certificate."""
        return np.array([r.certified for r in self.results], dtype=bool)

    def columns(self) -> dict[str, npt.NDArray[Any]]:
        """One column per field of :meth:`TuneResult.as_dict`, after the ``meta`` columns.

        Examples
        --------
        >>> from stringstab.tuning import project
        >>> rs = TuneResults((project([0.9, -0.5, 1.1], tau=0.1, delta=0.2, headway=1.1),))
        >>> list(rs.columns())[:4], bool(rs.columns()["certified"][0])
        (['method', 'k_x_in', 'k_v_in', 'k_a_in'], True)
        """
        cols: dict[str, npt.NDArray[Any]] = {k: np.asarray(v) for k, v in self.meta.items()}
        rows = [r.as_dict() for r in self.results]
        keys = list(rows[0]) if rows else list(TuneResult.__dataclass_fields__)
        for k in keys:
            cols[k] = np.array([row[k] for row in rows])
        return cols

    def records(self) -> list[dict[str, Any]]:
        """One dict per result: the ``meta`` values, then :meth:`TuneResult.as_dict`."""
        meta = {k: np.asarray(v).tolist() for k, v in self.meta.items()}
        return [{**{k: v[i] for k, v in meta.items()}, **r.as_dict()}
                for i, r in enumerate(self.results)]

    def summary(self) -> dict[str, dict[str, Any]]:
        """Per-method counts of the outcomes and the median distance the repaired gains moved.

        Returns
        -------
        dict of str to dict
            For each method: ``n`` (outputs), ``certified``, ``repaired`` (moved and certified),
            ``unchanged``, ``not_certified`` and ``median_distance_moved`` (over the outputs
            that moved, certified or not; 0.0 when none moved).
        """
        out: dict[str, dict[str, Any]] = {}
        methods = self.methods or tuple(dict.fromkeys(r.method for r in self.results))
        for m in methods:
            rs = [r for r in self.results if r.method == m]
            moved = [r.distance for r in rs if r.status in ("repaired", "moved_not_certified")]
            out[m] = {
                "n": len(rs),
                "certified": sum(r.certified for r in rs),
                "repaired": sum(r.status == "repaired" for r in rs),
                "unchanged": sum(r.status == "unchanged" for r in rs),
                "not_certified": sum(not r.certified for r in rs),
                "median_distance_moved": float(np.median(moved)) if moved else 0.0,
            }
        return out

    @classmethod
    def collect(cls, results: Sequence[TuneResult], meta: Mapping[str, Any] | None = None,
                methods: Sequence[str] = ()) -> TuneResults:
        """Results (and per-result ``meta`` columns) as a :class:`TuneResults`.

        Parameters
        ----------
        results : sequence of TuneResult
            One result per input triple.
        meta : mapping of str to array_like, optional
            Extra columns, one value per result (e.g. the input's row or τ, δ, T*).
        methods : sequence of str
            The repair methods that were run.

        Returns
        -------
        TuneResults
            The collection.
        """
        return cls(tuple(results), {k: np.asarray(v) for k, v in (meta or {}).items()},
                   tuple(methods))


def wdist(K: Array, K0: Array, w: Array) -> Array:
    """Weighted Euclidean distance(s) of the row(s) of K from K0.

    Parameters
    ----------
    K : ndarray, shape (3,) or (n, 3)
        Gain triple(s) (k_x, k_v, k_a).
    K0 : ndarray, shape (3,)
        The reference gains.
    w : ndarray, shape (3,)
        Weights (w_x, w_v, w_a).

    Returns
    -------
    ndarray, shape () or (n,)
        ‖K − K0‖_W = sqrt(Σ_i w_i (K_i − K0_i)²) of each triple.
    """
    d = np.asarray(K, dtype=float) - K0
    return np.asarray(np.sqrt(np.sum(w * d * d, axis=-1)))


def triple(k: Array) -> tuple[float, float, float]:
    """The three gains as Python floats.

    Parameters
    ----------
    k : ndarray, shape (3,)
        Gains (k_x, k_v, k_a).

    Returns
    -------
    tuple of float
        ``(k_x, k_v, k_a)``.
    """
    return float(k[0]), float(k[1]), float(k[2])


@dataclass(frozen=True)
class VerdictAndGain:
    """What a :class:`TuneResult` reports of the exact certificate: verdict and sup |Γ|.

    Built from a full :class:`~stringstab.certify.continuous.Certificate` or, in the
    projection's fast path, from :func:`stringstab.certify.api.check` (the same
    sound decision without the reporting extras).  A certified triple has
    ‖Γ‖_{H∞} = 1 exactly (Γ(0) = 1 and |Γ(jω)| ≤ 1), which is what
    :func:`~stringstab.certify.api.certify` reports for it too, so no peak
    search is needed; for any other verdict the full certificate is computed.
    """

    verdict: verdicts.Verdict
    sup_gain: float

    @property
    def certified(self) -> bool:
        """The verdict is :attr:`~stringstab.certify.verdicts.Verdict.CERTIFIED`."""
        return self.verdict is verdicts.Verdict.CERTIFIED

    @classmethod
    def of(cls, cert: Certificate) -> VerdictAndGain:
        """The verdict and sup |Γ| of a full certificate.

        Parameters
        ----------
        cert : Certificate
            The exact certificate of one triple.

        Returns
        -------
        VerdictAndGain
            ``cert.verdict`` (as a :class:`~stringstab.certify.verdicts.Verdict`) and
            ``float(cert.sup_gain)``.
        """
        return cls(verdicts.Verdict(cert.verdict), float(cert.sup_gain))


#: What a triple that :func:`stringstab.certify.api.check` certified reports: certified,
#: and ‖Γ‖_H∞ = 1 (see :class:`VerdictAndGain`).
CERTIFIED_BY_CHECK = VerdictAndGain(verdicts.Verdict.CERTIFIED, 1.0)


def make_result(method: str, K0: Array, K: Array, cert: Certificate | VerdictAndGain, status: str,
                w: Array, iterations: int, t0: float, message: str, **details: Any) -> TuneResult:
    """A :class:`TuneResult` of ``method`` that moved ``K0`` to ``K``, timed from ``t0``.

    Parameters
    ----------
    method : str
        The repair method's name (``"projection"``, ``"region-growing"``).
    K0 : ndarray, shape (3,)
        The input gains (k_x [1/s²], k_v [1/s], k_a [-]; IDL eq 4).
    K : ndarray, shape (3,)
        The output gains.
    cert : Certificate or VerdictAndGain
        The exact certificate of K (or the verdict and sup |Γ| taken from it).
    status : str
        The method's exit status, recorded as is except ``"repaired"`` for an output the exact
        certificate does not certify, which is recorded as ``"moved_not_certified"`` (a table
        never says "repaired" beside "certified: no").
    w : ndarray, shape (3,)
        Weights of the reported distance ‖K − K0‖_W (:func:`wdist`).
    iterations : int
        Iterations the method ran.
    t0 : float
        ``time.perf_counter()`` at the start; ``seconds`` is measured from it.
    message : str
        Human-readable outcome.
    **details
        Method-specific extras, stored in ``TuneResult.details``.

    Returns
    -------
    TuneResult
        ``certified`` and ``verdict`` come from ``cert``, never from ``status``.
    """
    v = cert if isinstance(cert, VerdictAndGain) else VerdictAndGain.of(cert)
    if status == "repaired" and not v.certified:
        status = "moved_not_certified"
    return TuneResult(
        method=method, k_in=triple(K0), k=triple(K), certified=v.certified,
        verdict=v.verdict, status=status, distance=float(wdist(K, K0, w)),
        iterations=iterations, seconds=time.perf_counter() - t0, message=message,
        sup_gain=v.sup_gain, details=details,
    )

