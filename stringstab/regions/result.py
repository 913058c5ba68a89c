"""The result of a region map: :class:`RegionMap`, its classes, shares and summary.

A :class:`RegionMap` holds every per-point verdict of :func:`stringstab.regions.region_map`
and owns what is computed from them (class maps, shares, disagreements, the summary, a
slice).  Its files (metadata, per-point columns, :meth:`RegionMap.save_npz`,
:meth:`RegionMap.save_csv`, :func:`load_npz`) are :mod:`stringstab.regions.storage`'s job;
the methods here call it.  The names and codes (:data:`GAIN_NAMES`, :data:`VERDICT_LABELS`,
the classes) are :mod:`stringstab.regions.codes`', re-exported here.
"""

from __future__ import annotations

import builtins
import os
from dataclasses import dataclass, field
from itertools import combinations
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from ..certify.verdicts import INCONCLUSIVE, Verdict
from ..errors import StringStabError
from ..params import Box, Params
from . import storage
from .codes import CERTIFICATE_METHODS, EXACT_CLASSES, STABLE, TYPE_CLASSES, TYPE_TO_CLASS, UNSTABLE
from .codes import CONTINUOUS as CONTINUOUS  # kept importable from here (their home: codes)
from .codes import GAIN_NAMES as GAIN_NAMES
from .codes import METHODS as METHODS
from .codes import VERDICT_LABELS as VERDICT_LABELS
from .report import render_report

# the names and codes stay importable from here (stringstab.regions.result.VERDICT_LABELS, ...);
# their home is stringstab.regions.codes
__all__ = ["RegionMap", "describe_params", "load_npz"]

Array = npt.NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class RegionMap:
    """Verdicts of each method on a grid of gains (see the module docstring).

    Every per-point array has the grid's shape ``tuple(len(a) for a in
    axes.values())``: index ``[i, j]`` (or ``[i, j, k]``) is the point whose
    first axis gain is ``axes[first][i]``, and so on.

    Attributes
    ----------
    axes : dict of str to ndarray
        The gains varied, in axis order (two or three of ``k_x, k_v, k_a``),
        each with its increasing grid coordinates.
    fixed : dict of str to float
        The gain held fixed on a 2-D slice (empty for a 3-D map).
    params : Params or Box
        τ, δ, T*: a point, or a box of intervals (the robust certificate).
    methods : tuple of str
        The methods evaluated: a subset of :data:`METHODS` for the continuous loop at one
        τ, δ, T*; ``exact`` and optionally :data:`CONTINUOUS` for a sampled or robust map.
    hurwitz : ndarray of bool
        Internally stable: Γ Hurwitz; the sampled Δ(z) Schur (``sample_time``); every
        member of the box (a :class:`~stringstab.params.Box`).
    type : ndarray of int8 or None
        Stability type 1-4 (I-IV) from the derived Ψ (None for a sampled or robust map:
        the Taylor types are of the continuous loop at one τ, δ, T*).
    type_printed : ndarray of int8 or None
        Stability type from the printed Ψ (when ``printed`` is evaluated).
    verdict : dict of str to ndarray of int8
        Per method, codes into :data:`VERDICT_LABELS` (0 = says string stable).
    prop1 : dict of str to ndarray of bool
        Proposition 1 alone (without Hurwitz) for ``taylor`` and ``printed``.
    sup_gain, margin : ndarray of float or None
        ‖Γ‖_{H∞} and min_ω g(ω) from the exact certificate (when evaluated); for a
        sampled map sup_θ |H(e^{jθ})| and min g_H; for a box, the sup gain at the witness
        member (a lower bound on the worst member's) and the smallest margin found.
    version : str
        ``stringstab.__version__`` of the tool that computed the map.
    sample_time : float or None
        H (s) of a sampled-data map (``exact`` is then the sampled certificate); None for
        the continuous loop.
    heterogeneous : bool
        Sampled box only: the predecessor's lag ranged over the τ box independently.
    hurwitz_continuous : ndarray of bool or None
        Internal stability of the continuous loop, when :data:`CONTINUOUS` is evaluated.
    message_period : float or None
        The V2V message period N·H (s) of a multi-rate map (``exact`` is then the multi-rate
        certificate); None otherwise.
    stability_undecided : ndarray of bool or None
        θ_r box maps: internal stability over the box neither proven nor disproven within the
        budget (``stability == "undecided"`` of the robust θ_r certificate); such points are
        never drawn as "not internally stable".  None: no such point can occur.
    """

    axes: dict[str, Array]
    fixed: dict[str, float]
    params: Params | Box
    methods: tuple[str, ...]
    hurwitz: npt.NDArray[np.bool_]
    type: npt.NDArray[np.int8] | None
    verdict: dict[str, npt.NDArray[np.int8]]
    prop1: dict[str, npt.NDArray[np.bool_]] = field(default_factory=dict)
    type_printed: npt.NDArray[np.int8] | None = None
    sup_gain: Array | None = None
    margin: Array | None = None
    version: str = ""
    sample_time: float | None = None
    heterogeneous: bool = True
    hurwitz_continuous: npt.NDArray[np.bool_] | None = None
    message_period: float | None = None
    stability_undecided: npt.NDArray[np.bool_] | None = None

    @property
    def is_box(self) -> bool:
        """The parameters are a box of intervals (the robust certificate)."""
        return isinstance(self.params, Box)

    @property
    def loop(self) -> str:
        """Which loop ``exact`` certifies, in words (``continuous``, ``sampled Δt = 0.1 s``, ...)."""
        what = "continuous" if self.sample_time is None else f"sampled Δt = {self.sample_time:g} s"
        if self.message_period is not None:
            what += f", V2V messages every {self.message_period:g} s"
        return f"{what}, robust over the box" if self.is_box else what

    # ---------------------------------------------------------------- shape and points
    @property
    def shape(self) -> tuple[int, ...]:
        """The grid shape."""
        return tuple(a.size for a in self.axes.values())

    @property
    def ndim(self) -> int:
        """2 for a slice, 3 for a volume."""
        return len(self.axes)

    @property
    def size(self) -> int:
        """Number of grid points."""
        return int(np.prod(self.shape))

    @property
    def axis_names(self) -> tuple[str, ...]:
        """Names of the gains on the axes, in order."""
        return tuple(self.axes)

    def gains(self) -> tuple[Array, Array, Array]:
        """k_x, k_v, k_a at every grid point, each of the grid's shape."""
        grids = np.meshgrid(*self.axes.values(), indexing="ij")
        by_name = dict(zip(self.axes, grids))
        for name, v in self.fixed.items():
            by_name[name] = np.full(self.shape, v)
        return by_name["k_x"], by_name["k_v"], by_name["k_a"]

    # ---------------------------------------------------------------- classes and shares
    def _check_method(self, method: str) -> None:
        if method not in self.methods:
            raise StringStabError(
                f"method must be one of those evaluated in this map {list(self.methods)}; got {method!r}"
            )

    def stable(self, method: str) -> npt.NDArray[np.bool_]:
        """Where ``method`` says string stable (certified, or Hurwitz ∧ Proposition 1).

        Parameters
        ----------
        method : str
            One of the map's :attr:`methods` (``"exact"``, ``"continuous"``, ``"taylor"``,
            ``"printed"``).

        Returns
        -------
        bool ndarray, shape :attr:`shape`
            True where the method's verdict is string stable.

        Raises
        ------
        StringStabError
            If ``method`` was not evaluated in this map.
        """
        self._check_method(method)
        return np.asarray(self.verdict[method] == STABLE)

    def class_names(self, method: str) -> tuple[str, ...]:
        """Names of the class codes of :meth:`classes` for ``method``.

        Parameters
        ----------
        method : str
            One of the map's :attr:`methods`.

        Returns
        -------
        tuple of str
            :data:`EXACT_CLASSES` for a certificate, :data:`TYPE_CLASSES` for a Taylor method;
            entry i names code i.

        Raises
        ------
        StringStabError
            If ``method`` was not evaluated in this map.
        """
        self._check_method(method)
        return EXACT_CLASSES if method in CERTIFICATE_METHODS else TYPE_CLASSES

    def classes(self, method: str) -> npt.NDArray[np.int8]:
        """Class code of every point for the class map of ``method``.

        ``exact`` (and ``continuous``): 0 not internally stable, 1 not certified,
        2 inconclusive, 3 certified (:data:`EXACT_CLASSES`).  ``taylor`` / ``printed``: 0 not
        internally stable, then 1 type III, 2 type IV, 3 type I, 4 type II of
        that method's Ψ (:data:`TYPE_CLASSES`; IDL §3.3).

        Parameters
        ----------
        method : str
            One of the map's :attr:`methods`.

        Returns
        -------
        int8 ndarray, shape :attr:`shape`
            The class codes.

        Raises
        ------
        StringStabError
            If ``method`` was not evaluated in this map.
        """
        self._check_method(method)
        if method in CERTIFICATE_METHODS:
            v = self.verdict[method]
            stable = self.hurwitz if method == "exact" else self.hurwitz_continuous
            assert stable is not None
            c = np.full(self.shape, 3, dtype=np.int8)
            c[v == UNSTABLE] = 1
            c[(v == UNSTABLE) & ~stable] = 0
            if method == "exact" and self.stability_undecided is not None:  # not proven unstable
                c[(v == UNSTABLE) & self.stability_undecided] = 1
            c[v == INCONCLUSIVE] = 2
            return c
        t = self.type if method == "taylor" else self.type_printed
        assert t is not None
        c = TYPE_TO_CLASS[t]
        return np.where(self.hurwitz, c, np.int8(0)).astype(np.int8)

    def class_shares(self) -> dict[str, dict[str, float]]:
        """Share of grid points in each class of each method's class map.

        Examples
        --------
        >>> from stringstab.regions import region_map
        >>> m = region_map({"k_x": np.linspace(-1, 1, 5), "k_v": np.linspace(-1, 1, 5)},
        ...                {"k_a": 0.5}, tau=0.1, delta=0.2, headway=1.1, methods=("taylor",))
        >>> m.class_shares()["taylor"]["not internally stable"]
        0.72
        """
        out = {}
        for m in self.methods:
            counts = np.bincount(self.classes(m).ravel(), minlength=len(self.class_names(m)))
            out[m] = {name: float(c) / self.size for name, c in zip(self.class_names(m), counts)}
        return out

    def verdict_shares(self) -> dict[str, dict[str, float]]:
        """Share of grid points of each verdict of each method."""
        out = {}
        for m in self.methods:
            counts = np.bincount(self.verdict[m].ravel(), minlength=3)
            out[m] = {lab: float(c) / self.size for lab, c in zip(VERDICT_LABELS[m], counts)
                      if m in CERTIFICATE_METHODS or lab != Verdict.INCONCLUSIVE}
        return out

    def disagreements(self) -> dict[str, int]:
        """Number of points where methods disagree on string stability.

        One entry ``"a vs b"`` per pair of evaluated methods (points where both
        decide and they differ), ``"any"`` (points where no method is
        inconclusive and not all agree) and ``"inconclusive"`` (points where the
        exact certificate is inconclusive).
        """
        out: dict[str, int] = {}
        decided = np.ones(self.shape, dtype=bool)
        for m in self.methods:
            decided &= self.verdict[m] != INCONCLUSIVE
        for a, b in combinations(self.methods, 2):
            out[f"{a} vs {b}"] = int(np.count_nonzero(decided & (self.stable(a) != self.stable(b))))
        st = [self.stable(m) for m in self.methods]
        differ = np.zeros(self.shape, dtype=bool)
        for s in st[1:]:
            differ |= s != st[0]
        out["any"] = int(np.count_nonzero(decided & differ))
        out["inconclusive"] = int(np.count_nonzero(~decided))
        return out

    def summary(self) -> dict[str, Any]:
        """Metadata, class shares, verdict shares and disagreements, JSON-ready."""
        return {
            **self.metadata(),
            "n": self.size,
            "class_shares": self.class_shares(),
            "verdict_shares": self.verdict_shares(),
            "disagreements": self.disagreements(),
        }

    def report(self) -> str:
        """A few lines for people: the grid, class shares per method, disagreements.

        See :func:`stringstab.regions.report.render_report`.
        """
        return render_report(self)

    def title(self) -> str:
        """A one-line description: the fixed gain, the parameters (or the box), the sample time."""
        parts = [f"{k} = {v:g}" for k, v in self.fixed.items()]
        parts.append(describe_params(self.params))
        if self.sample_time is not None:
            parts.append(f"sampled Δt = {self.sample_time:g} s")
        if self.message_period is not None:
            parts.append(f"messages every {self.message_period:g} s")
        return "; ".join(parts)

    # ---------------------------------------------------------------- slicing
    def slice(self, gain: str, value: float) -> RegionMap:
        """The 2-D slice of a 3-D map at the grid coordinate of ``gain`` nearest ``value``.

        Parameters
        ----------
        gain : {"k_x", "k_v", "k_a"}
            The axis to fix.
        value : float
            The gain value; the nearest grid coordinate is taken (and recorded in ``fixed``).

        Returns
        -------
        RegionMap
            The 2-D map over the two other gains, with the same parameters and methods.

        Raises
        ------
        StringStabError
            If the map is not 3-D or ``gain`` is not one of its axes.
        """
        if self.ndim != 3:
            raise StringStabError(f"slice needs a 3-D map; got a {self.ndim}-D map")
        if gain not in self.axes:
            raise StringStabError(f"gain must be one of {list(self.axes)}; got {gain!r}")
        ax = list(self.axes).index(gain)
        k = int(np.argmin(np.abs(self.axes[gain] - value)))

        def take(a: Any) -> Any:
            return None if a is None else np.take(a, k, axis=ax)

        return RegionMap(
            axes={n: a for n, a in self.axes.items() if n != gain},
            fixed={gain: float(self.axes[gain][k])}, params=self.params, methods=self.methods,
            hurwitz=take(self.hurwitz), type=take(self.type),
            verdict={m: take(v) for m, v in self.verdict.items()},
            prop1={m: take(v) for m, v in self.prop1.items()},
            type_printed=take(self.type_printed), sup_gain=take(self.sup_gain),
            margin=take(self.margin), version=self.version, sample_time=self.sample_time,
            heterogeneous=self.heterogeneous, hurwitz_continuous=take(self.hurwitz_continuous),
            message_period=self.message_period, stability_undecided=take(self.stability_undecided),
        )

    # ---------------------------------------------------------------- files
    # (stringstab.regions.storage: the map's files apart from the map)
    def metadata(self) -> dict[str, Any]:
        """Parameters, axes, methods, code tables and the tool version (for files).

        See :func:`stringstab.regions.storage.metadata`.
        """
        return storage.metadata(self)

    def fields(self) -> dict[str, npt.NDArray[Any]]:
        """The per-point arrays by name (``hurwitz``, ``type``, ``verdict_<method>``, ...).

        See :func:`stringstab.regions.storage.fields`.
        """
        return storage.fields(self)

    _fields = fields  # the name used before RegionMap owned its columns

    def columns(self) -> dict[str, npt.NDArray[Any]]:
        """One column per field, one row per grid point (flattened in C order), for people.

        ``k_x, k_v, k_a``, ``hurwitz``, ``type`` (I-IV), ``type_printed``, one verdict
        column per method (its labels, :data:`VERDICT_LABELS`), ``sup_gain`` and
        ``margin`` (when evaluated): the columns of :meth:`save_csv`
        (:func:`stringstab.regions.storage.columns`).

        Examples
        --------
        >>> from stringstab.regions import region_map
        >>> m = region_map({"k_x": [0.9, 1.3], "k_v": [-0.5, 0.0]}, {"k_a": 1.1},
        ...                tau=0.1, delta=0.2, headway=1.1, methods="taylor")
        >>> list(m.columns()), m.columns()["taylor"].tolist()
        (['k_x', 'k_v', 'k_a', 'hurwitz', 'type', 'taylor'], ['unstable', 'unstable', 'unstable', 'unstable'])
        """
        return storage.columns(self)

    @property
    def n_columns(self) -> int:
        """Number of :meth:`columns` (without forming them)."""
        return len(storage.categorical_columns(self))

    def records(self) -> list[dict[str, Any]]:
        """:meth:`columns` as one dict per grid point (small maps; use the columns for large)."""
        cols = self.columns()
        return [dict(zip(cols, row)) for row in zip(*(c.tolist() for c in cols.values()))]

    def save_npz(self, path: str | os.PathLike[str]) -> Path:
        """Write the map to a compressed NPZ file with its metadata, atomically.

        The archive holds ``axis_<gain>`` coordinates, one array per field and ``metadata``
        (JSON: the parameters and the tool version); :func:`load_npz` reads it back
        (:func:`stringstab.regions.storage.save_npz`).

        Parameters
        ----------
        path : str or path-like
            The file to write.

        Returns
        -------
        Path
            ``path``.
        """
        return storage.save_npz(self, path)

    def save_csv(self, path: str | os.PathLike[str]) -> Path:
        """Write one CSV row per grid point (columns :meth:`columns`), after ``#`` metadata lines.

        See :func:`stringstab.regions.storage.save_csv` for the layout; written atomically.

        Parameters
        ----------
        path : str or path-like
            The file to write.

        Returns
        -------
        Path
            The file written.
        """
        return storage.save_csv(self, path)

    def csv_text(self, rows: builtins.slice | None = None, *, head: bool = True) -> str:
        """The text of :meth:`save_csv`, or of the grid points ``rows`` only (C order).

        ``head=False`` leaves out the ``#`` lines and the header, so that the texts of
        consecutive row ranges concatenate to the whole file
        (:func:`stringstab.regions.storage.csv_text`).

        Examples
        --------
        >>> from stringstab.regions import region_map
        >>> m = region_map({"k_x": [0.9, 1.3], "k_v": [-0.5, 0.0]}, {"k_a": 1.1},
        ...                tau=0.1, delta=0.2, headway=1.1, methods="taylor")
        >>> m.csv_text(slice(0, 2)) + m.csv_text(slice(2, None), head=False) == m.csv_text()
        True
        """
        return storage.csv_text(self, rows, head=head)


def load_npz(path: str | os.PathLike[str]) -> RegionMap:
    """Read a map written by :meth:`RegionMap.save_npz`.

    Parameters
    ----------
    path : str or path-like
        The NPZ file (read by :func:`stringstab.regions.storage.read_map`).

    Returns
    -------
    RegionMap
        The map, with its axes, fixed gains, parameters (a :class:`~stringstab.params.Params`
        or a :class:`~stringstab.params.Box`), methods and per-point fields.

    Raises
    ------
    StringStabError
        If the file is not a stringstab region map.
    """
    return RegionMap(**storage.read_map(path))


def describe_params(p: Params | Box) -> str:
    """``τ = 0.1 s, δ = 0.2 s, T* = 1.1 s``, intervals as ``τ ∈ [0.1, 0.3] s``.

    Parameters
    ----------
    p : Params or Box
        Actuator lag τ (IDL eq 7), communication delay δ (eq 4), time headway T* (eq 3) and,
        when not 0, the reaction delay θ_r (issue 25), in s, each a value or an interval.

    Returns
    -------
    str
        One line; a degenerate interval is written as a value.

    Examples
    --------
    >>> describe_params(Box((0.1, 0.3), (0.2, 0.2), (1.1, 1.1)))
    'τ ∈ [0.1, 0.3] s, δ = 0.2 s, T* = 1.1 s'
    >>> describe_params(Params(0.1, 0.2, 1.1, reaction_delay=0.2))  # θ_r only when > 0
    'τ = 0.1 s, δ = 0.2 s, T* = 1.1 s, θ_r = 0.2 s'
    """
    parts = []
    for sym, (lo, hi) in zip(("τ", "δ", "T*", "θ_r"), Box.of(p).as_dict().values()):
        parts.append(f"{sym} = {lo:g} s" if lo == hi else f"{sym} ∈ [{lo:g}, {hi:g}] s")
    return ", ".join(parts)

