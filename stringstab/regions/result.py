"""The result of a region map: :class:`RegionMap`, its classes, shares, columns and files.

A :class:`RegionMap` holds every per-point verdict of :func:`stringstab.regions.region_map`
and owns what is computed from them (class maps, shares, disagreements, the per-point
columns, the summary) and its files (:meth:`RegionMap.save_npz`, :meth:`RegionMap.save_csv`,
:func:`load_npz`, in the formats of :mod:`stringstab.regions.files`).
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

from ..certify.criteria import TYPE_NAMES
from ..certify.verdicts import CERTIFIED, INCONCLUSIVE, NOT_CERTIFIED, VERDICTS, Verdict
from ..errors import StringStabError
from ..io import atomic_write_text, dumps_json
from ..params import Box, Params
from .files import FORMAT, csv_text, read_npz, write_npz
from .report import render_report

__all__ = [
    "CONTINUOUS",
    "EXACT_CLASSES",
    "GAIN_NAMES",
    "METHODS",
    "STABLE",
    "TYPE_CLASSES",
    "UNSTABLE",
    "VERDICT_LABELS",
    "RegionMap",
    "describe_params",
    "load_npz",
]

Array = npt.NDArray[np.float64]

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
_CERTIFICATES = ("exact", CONTINUOUS)
#: Classes of the ``taylor`` and ``printed`` class maps, by code 0-4.
TYPE_CLASSES: tuple[str, ...] = (
    "not internally stable", "type III", "type IV", "type I", "type II",
)
#: Classes of the ``exact`` class map, by code 0-3: not internally stable, then the verdicts.
EXACT_CLASSES: tuple[str, ...] = (
    "not internally stable", Verdict.NOT_CERTIFIED.words, Verdict.INCONCLUSIVE.words,
    Verdict.CERTIFIED.words,
)
# stability_type code (1 = I, ..., 4 = IV) -> TYPE_CLASSES code
_TYPE_TO_CLASS = np.array([0, 3, 4, 1, 2], dtype=np.int8)


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
        return EXACT_CLASSES if method in _CERTIFICATES else TYPE_CLASSES

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
        if method in _CERTIFICATES:
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
        c = _TYPE_TO_CLASS[t]
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
                      if m in _CERTIFICATES or lab != Verdict.INCONCLUSIVE}
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
    def metadata(self) -> dict[str, Any]:
        """Parameters, axes, methods, code tables and the tool version (for files)."""
        return {
            "format": FORMAT,
            "stringstab_version": self.version,
            "params": self.params.as_dict(),
            **({} if self.sample_time is None else {"sample_time": self.sample_time}),
            **({} if self.message_period is None else {"message_period": self.message_period}),
            **({"heterogeneous": self.heterogeneous}
               if self.sample_time is not None and self.is_box else {}),
            "axes": {n: {"min": float(a[0]), "max": float(a[-1]), "n": int(a.size)}
                     for n, a in self.axes.items()},
            "fixed": dict(self.fixed),
            "methods": list(self.methods),
            "verdict_labels": {m: list(VERDICT_LABELS[m]) for m in self.methods},
            "type_names": {str(k): v for k, v in TYPE_NAMES.items()},
        }

    def fields(self) -> dict[str, npt.NDArray[Any]]:
        """The per-point arrays by name (``hurwitz``, ``type``, ``verdict_<method>``, ...)."""
        f: dict[str, npt.NDArray[Any]] = {"hurwitz": self.hurwitz}
        if self.type is not None:
            f["type"] = self.type
        if self.hurwitz_continuous is not None:
            f["hurwitz_continuous"] = self.hurwitz_continuous
        if self.stability_undecided is not None:
            f["stability_undecided"] = self.stability_undecided
        if self.type_printed is not None:
            f["type_printed"] = self.type_printed
        for m, code in self.verdict.items():
            f[f"verdict_{m}"] = code
        for m, ok in self.prop1.items():
            f[f"prop1_{m}"] = ok
        if self.sup_gain is not None:
            f["sup_gain"] = self.sup_gain
        if self.margin is not None:
            f["margin"] = self.margin
        return f

    _fields = fields  # the name used before RegionMap owned its columns

    def columns(self) -> dict[str, npt.NDArray[Any]]:
        """One column per field, one row per grid point (flattened in C order), for people.

        ``k_x, k_v, k_a``, ``hurwitz``, ``type`` (I-IV), ``type_printed``, one verdict
        column per method (its labels, :data:`VERDICT_LABELS`), ``sup_gain`` and
        ``margin`` (when evaluated): the columns of :meth:`save_csv`.

        Examples
        --------
        >>> from stringstab.regions import region_map
        >>> m = region_map({"k_x": [0.9, 1.3], "k_v": [-0.5, 0.0]}, {"k_a": 1.1},
        ...                tau=0.1, delta=0.2, headway=1.1, methods="taylor")
        >>> list(m.columns()), m.columns()["taylor"].tolist()
        (['k_x', 'k_v', 'k_a', 'hurwitz', 'type', 'taylor'], ['unstable', 'unstable', 'unstable', 'unstable'])
        """
        cached = self.__dict__.get("_columns")
        if cached is None:
            cached = {k: np.asarray(v) for k, v in self._categorical_columns().items()}
            object.__setattr__(self, "_columns", cached)  # computed once (the map is immutable)
        return dict(cached)

    @property
    def n_columns(self) -> int:
        """Number of :meth:`columns` (without forming them)."""
        return len(self._categorical_columns())

    def _categorical_columns(self) -> dict[str, Any]:
        """:meth:`columns` with the coordinates and labels as :class:`~stringstab.io.Categorical`.

        Categorical columns are codes into a few distinct values: what the CSV writer formats
        fastest.
        """
        cached = self.__dict__.get("_categorical")
        if cached is not None:
            return dict(cached)
        from ..io import Categorical

        shape = self.shape
        cols: dict[str, Any] = {}
        index = np.indices(shape).reshape(len(shape), -1)
        axis_pos = {name: i for i, name in enumerate(self.axis_names)}
        for name in GAIN_NAMES:  # the axes' values, or the fixed value, spread over the grid
            if name in axis_pos:
                cols[name] = Categorical(index[axis_pos[name]], np.asarray(self.axes[name], float))
            else:
                cols[name] = Categorical(np.zeros(self.size, dtype=np.intp),
                                         np.asarray([self.fixed[name]], dtype=float))
        names = np.array(["", *TYPE_NAMES.values()])
        cols["hurwitz"] = self.hurwitz.ravel()
        if self.type is not None:
            cols["type"] = Categorical(self.type.ravel(), names)
        if self.type_printed is not None:
            cols["type_printed"] = Categorical(self.type_printed.ravel(), names)
        for m in self.methods:
            cols[m] = Categorical(self.verdict[m].ravel(), np.array(VERDICT_LABELS[m]))
        if self.sup_gain is not None:
            cols["sup_gain"] = self.sup_gain.ravel()
        if self.margin is not None:
            cols["margin"] = self.margin.ravel()
        object.__setattr__(self, "_categorical", cols)  # computed once (the map is immutable)
        return dict(cols)

    def records(self) -> list[dict[str, Any]]:
        """:meth:`columns` as one dict per grid point (small maps; use the columns for large)."""
        cols = self.columns()
        return [dict(zip(cols, row)) for row in zip(*(c.tolist() for c in cols.values()))]

    def save_npz(self, path: str | os.PathLike[str]) -> Path:
        """Write the map to a compressed NPZ file with its metadata.

        The archive holds ``axis_<gain>`` coordinates, one array per field
        (``hurwitz``, ``type``, ``verdict_<method>``, ...) and ``metadata``, a
        JSON string with the parameters and the tool version.  Read it back with
        :func:`load_npz`.

        Parameters
        ----------
        path : str or path-like
            The file to write (atomically).

        Returns
        -------
        Path
            ``path``.
        """
        return write_npz(path, self.axes, self.fields(), self.metadata())

    def save_csv(self, path: str | os.PathLike[str]) -> Path:
        """Write one CSV row per grid point, after ``#`` lines with the metadata.

        Columns: :meth:`columns`.  The first line is ``# stringstab <version> region
        map``, the second ``# `` followed by :meth:`metadata` as JSON; then the header
        and the rows, written column by column (:mod:`stringstab.io`'s writer: numbers
        in their shortest round-trip form, booleans ``True``/``False``, a non-finite
        number, such as ``sup_gain`` where Γ is not internally stable, as an empty field).

        Parameters
        ----------
        path : str or path-like
            The file to write (atomically).

        Returns
        -------
        Path
            The file written.
        """
        return atomic_write_text(path, self.csv_text(), what="region map CSV")

    def csv_text(self, rows: builtins.slice | None = None, *, head: bool = True) -> str:
        """The text of :meth:`save_csv`, or of the grid points ``rows`` only (C order).

        ``head=False`` leaves out the ``#`` lines and the header, so that the texts of
        consecutive row ranges concatenate to the whole file (two processes can write one).

        Parameters
        ----------
        rows : slice, optional
            The grid points (flattened in C order) to write; None for all.
        head : bool
            Start with the ``#`` lines and the header.

        Returns
        -------
        str
            The CSV text.

        Examples
        --------
        >>> from stringstab.regions import region_map
        >>> m = region_map({"k_x": [0.9, 1.3], "k_v": [-0.5, 0.0]}, {"k_a": 1.1},
        ...                tau=0.1, delta=0.2, headway=1.1, methods="taylor")
        >>> m.csv_text(slice(0, 2)) + m.csv_text(slice(2, None), head=False) == m.csv_text()
        True
        """
        comments = [f"stringstab {self.version} region map",
                    dumps_json(self.metadata(), indent=None).rstrip("\n")] if head else None
        cols = self._categorical_columns()
        if rows is not None:
            cols = {k: v[rows] for k, v in cols.items()}
        return csv_text(cols, comments)


def load_npz(path: str | os.PathLike[str]) -> RegionMap:
    """Read a map written by :meth:`RegionMap.save_npz`.

    Parameters
    ----------
    path : str or path-like
        The NPZ file.

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
    meta, data = read_npz(path)
    need = ("methods", "params", "axes", "fixed", "stringstab_version")
    missing = [k for k in need if k not in meta]
    arrays = ["hurwitz", *(f"axis_{n}" for n in meta.get("axes", ())),
              *(f"verdict_{m}" for m in meta.get("methods", ()))]
    missing += [k for k in arrays if k not in data]
    if missing:
        raise StringStabError(f"{path}: expected a region map with {', '.join(missing)}; "
                              f"found metadata keys {sorted(meta)} and arrays {sorted(data)}")
    methods = tuple(meta["methods"])
    p = meta["params"]
    params: Params | Box = (Box(*(tuple(p[k]) for k in ("tau", "delta", "headway")))
                            if isinstance(p["tau"], list) else Params(**p))
    return RegionMap(
        axes={n: data[f"axis_{n}"] for n in meta["axes"]},
        fixed={k: float(v) for k, v in meta["fixed"].items()},
        params=params, methods=methods,
        hurwitz=data["hurwitz"], type=data.get("type"),
        verdict={m: data[f"verdict_{m}"] for m in methods},
        prop1={m: data[f"prop1_{m}"] for m in methods if f"prop1_{m}" in data},
        type_printed=data.get("type_printed"), sup_gain=data.get("sup_gain"),
        margin=data.get("margin"), version=meta["stringstab_version"],
        sample_time=meta.get("sample_time"), heterogeneous=bool(meta.get("heterogeneous", True)),
        hurwitz_continuous=data.get("hurwitz_continuous"),
        message_period=meta.get("message_period"),
        stability_undecided=data.get("stability_undecided"),
    )


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

