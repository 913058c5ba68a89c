"""Stability-region maps: verdicts of every method on a grid of gains K = [k_x, k_v, k_a].

:func:`region_map` evaluates a grid over two gains (the third fixed) or over
all three, and returns a :class:`RegionMap` holding, per grid point,

* ``hurwitz``: internal stability of Γ (k_x > 0 and k_v + (T* − τ)k_x > 0,
  :func:`stringstab.criteria.hurwitz`);
* ``type``: the stability type I-IV of IDL §3.3 from the *derived* Ψ2, Ψ3, Λ
  (:func:`stringstab.criteria.stability_type`), and ``type_printed`` from the
  Ψ as printed (IDL eqs 13-15) when the ``printed`` method is requested;
* ``verdict[method]`` for each requested method:

  ``exact``
      the sound certificate with the exact delay
      (:func:`stringstab.certificate.certify_batch`): ``certified``,
      ``not_certified`` or ``inconclusive``;
  ``taylor``
      Proposition 1 (IDL eqs 12-15) with the *derived* Ψ and the corrected
      logic, **and** Hurwitz: ``stable`` or ``unstable``;
  ``printed``
      Proposition 1 with the Ψ and the logic *as printed*, **and** Hurwitz.

  Proposition 1 alone does not check internal stability (the printed logic
  ``(Ψ1, Ψ2, Ψ3 ≥ 0) ∨ Λ ≤ 0`` accepts gains with k_x < 0), so a map's Taylor
  verdicts require Hurwitz as well, like the exact one; the bare Proposition-1
  booleans are kept in ``prop1[method]``;
* ``sup_gain`` (‖Γ‖_{H∞} = sup_ω |Γ(jω)|, ``inf`` when Γ is not internally
  stable) and ``margin`` (min_ω g(ω) found) when ``exact`` is requested.

Classes of the class maps (:meth:`RegionMap.classes`):

* ``taylor`` / ``printed``: *not internally stable*, then the type of that
  method's Ψ: *type III* (Ψ3 < 0), *type IV* (Ψ3 ≥ 0, Ψ2 < 0, Λ > 0),
  *type I* (Ψ2, Ψ3 ≥ 0), *type II* (Ψ3 ≥ 0, Ψ2 < 0, Λ ≤ 0);
* ``exact``: *not internally stable* (‖Γ‖∞ = ∞), *not certified* (internally
  stable, some |Γ(jω)| > 1), *inconclusive*, *certified* (‖Γ‖∞ ≤ 1).

The types are defined from Ψ2, Ψ3, Λ only: a type I or II point with Ψ1 < 0
fails the derived Proposition 1, and the printed logic can accept a type III
point with Λ ≤ 0.  The class map shows the types; the verdicts are in
``verdict``.

Evaluation is chunked in blocks of grid points (memory bounded by the block
size, not the grid) and spread over worker processes.  The Taylor quantities
are evaluated as polynomials in one gain with coefficients on the plane of the
other two (Horner's rule, coefficients generated from the SymPy expressions of
:func:`stringstab.symbolic.derived_psi` and :func:`stringstab.printed.printed_psi`);
this agrees with :func:`stringstab.criteria.taylor_criteria` to round-off
(~1e-15 relative), so only grid points lying exactly on a boundary Ψ = 0 or
Λ = 0 can fall on the other side of it.

References
----------
IDL paper, Proposition 1 (eqs 12-15), §3.3 (types I-IV), Definition 1 (eq 10).
"""

from __future__ import annotations

import concurrent.futures as cf
import csv
import json
import math
import multiprocessing
import os
import sys
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from itertools import combinations
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from . import _generated as _gen
from .criteria import TYPE_NAMES, hurwitz, proposition1, stability_type
from .errors import StringStabError
from .params import Params

__all__ = [
    "EXACT_CLASSES",
    "GAIN_NAMES",
    "METHODS",
    "TYPE_CLASSES",
    "VERDICT_LABELS",
    "RegionMap",
    "load_npz",
    "region_map",
]

Array = npt.NDArray[np.float64]

#: The gains, in the order of K = [k_x, k_v, k_a] (IDL eq 4).
GAIN_NAMES: tuple[str, str, str] = ("k_x", "k_v", "k_a")
#: The methods a map can evaluate.
METHODS: tuple[str, str, str] = ("exact", "taylor", "printed")
#: Labels of the verdict codes 0, 1, 2 per method (code 0 means "says string stable").
VERDICT_LABELS: dict[str, tuple[str, str, str]] = {
    "exact": ("certified", "not_certified", "inconclusive"),
    "taylor": ("stable", "unstable", "inconclusive"),
    "printed": ("stable", "unstable", "inconclusive"),
}
#: Classes of the ``taylor`` and ``printed`` class maps, by code 0-4.
TYPE_CLASSES: tuple[str, ...] = (
    "not internally stable", "type III", "type IV", "type I", "type II",
)
#: Classes of the ``exact`` class map, by code 0-3.
EXACT_CLASSES: tuple[str, ...] = (
    "not internally stable", "not certified", "inconclusive", "certified",
)

_STABLE, _UNSTABLE, _INCONCLUSIVE = 0, 1, 2
# stability_type code (1 = I, ..., 4 = IV) -> TYPE_CLASSES code
_TYPE_TO_CLASS = np.array([0, 3, 4, 1, 2], dtype=np.int8)
_FORMAT = "stringstab-region-map/1"

#: Grid points per block: with the exact certificate, and with the Taylor criteria only.
EXACT_BLOCK = 16_384
TAYLOR_BLOCK = 1 << 19
#: Maps estimated to take less than this many seconds run in one process.
_PARALLEL_SECONDS = 0.5
_EXACT_SECONDS_PER_POINT = 2e-5
_TAYLOR_SECONDS_PER_POINT = 1.5e-7


# --------------------------------------------------------------------------- Taylor on a grid
def _psi_grid(
    source: str, names: tuple[str, str, str], x0: Array, x1: Array, x2: Array, p: Params
) -> tuple[Array, Array, Array, Array]:
    """Ψ1, Ψ2, Ψ3, Λ on the grid x0 × x1 × x2 (shape (n0, n1, n2)), by Horner in x0.

    The coefficients of each Ψ as a polynomial in the gain ``names[0]`` are generated
    from the SymPy expressions (:func:`stringstab._generated.psi_polynomials`).
    """
    shape = (x0.size, x1.size, x2.size)
    a0 = x0.reshape(-1, 1, 1)
    polys = _gen.psi_polynomials(
        source, names[0], **{names[1]: x1.reshape(1, -1, 1), names[2]: x2.reshape(1, 1, -1)},
        tau=p.tau, delta=p.delta, headway=p.headway)
    res = []
    for coeffs in polys:
        r = np.empty(shape)
        r[...] = coeffs[0]
        for c in coeffs[1:]:
            r *= a0
            r += c
        res.append(r)
    return res[0], res[1], res[2], res[3]


# --------------------------------------------------------------------------- blocks
@dataclass(frozen=True)
class _Spec:
    """What a worker needs to evaluate a block (picklable)."""

    names: tuple[str, str, str]  # gain on internal axis 0, 1, 2
    coords: tuple[Array, Array, Array]
    params: Params
    methods: tuple[str, ...]


def _eval_block(spec: _Spec, i0: int, i1: int, j0: int, j1: int) -> dict[str, Any]:
    """All fields on the block [i0:i1, j0:j1, :] of the internal 3-D grid."""
    x0 = spec.coords[0][i0:i1]
    x1 = spec.coords[1][j0:j1]
    x2 = spec.coords[2]
    p = spec.params
    shape = (x0.size, x1.size, x2.size)
    gains = {
        spec.names[0]: x0.reshape(-1, 1, 1),
        spec.names[1]: x1.reshape(1, -1, 1),
        spec.names[2]: x2.reshape(1, 1, -1),
    }
    out: dict[str, Any] = {}
    hz = np.broadcast_to(hurwitz(gains["k_x"], gains["k_v"], tau=p.tau, headway=p.headway), shape)
    out["hurwitz"] = hz
    sources = [("derived", "taylor")]
    if "printed" in spec.methods:
        sources.append(("printed", "printed"))
    for source, method in sources:
        psi1, psi2, psi3, lam = _psi_grid(source, spec.names, x0, x1, x2, p)
        out["type" if source == "derived" else "type_printed"] = stability_type(psi2, psi3, lam)
        if method in spec.methods:
            ok = proposition1(psi1, psi2, psi3, lam, source=source)
            out[f"prop1_{method}"] = ok
            out[f"verdict_{method}"] = np.where(ok & hz, _STABLE, _UNSTABLE).astype(np.int8)
    if "exact" in spec.methods:
        from .certificate import certify_batch

        full = [np.broadcast_to(gains[g], shape).ravel() for g in GAIN_NAMES]
        b = certify_batch(*full, tau=p.tau, delta=p.delta, headway=p.headway)
        code = np.full(b.verdict.shape, _INCONCLUSIVE, dtype=np.int8)
        code[b.verdict == "certified"] = _STABLE
        code[b.verdict == "not_certified"] = _UNSTABLE
        out["verdict_exact"] = code.reshape(shape)
        out["sup_gain"] = b.sup_gain.reshape(shape)
        out["margin"] = b.margin.reshape(shape)
    return out


def _blocks(n0: int, n1: int, n2: int, target: int) -> list[tuple[int, int, int, int]]:
    """Split the (n0, n1, n2) grid into blocks [i0:i1, j0:j1, :] of about ``target`` points."""
    row = n1 * n2
    if row <= target:
        step = max(1, target // row)
        return [(i, min(i + step, n0), 0, n1) for i in range(0, n0, step)]
    jstep = max(1, target // n2)
    return [(i, i + 1, j, min(j + jstep, n1)) for i in range(n0) for j in range(0, n1, jstep)]


def _warm(methods: tuple[str, ...], names: tuple[str, str, str]) -> None:
    """Run the certificate once (imports and caches; forked workers inherit them)."""
    if "exact" in methods:
        from .certificate import certify_batch

        certify_batch([1.0], [0.5], [0.2], tau=0.1, delta=0.2, headway=1.1)


def _cpu_count() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not Linux
        return os.cpu_count() or 1


# --------------------------------------------------------------------------- result
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
    params : Params
        τ, δ, T*.
    methods : tuple of str
        The methods evaluated, a subset of :data:`METHODS`.
    hurwitz : ndarray of bool
        Γ internally stable.
    type : ndarray of int8
        Stability type 1-4 (I-IV) from the derived Ψ.
    type_printed : ndarray of int8 or None
        Stability type from the printed Ψ (when ``printed`` is evaluated).
    verdict : dict of str to ndarray of int8
        Per method, codes into :data:`VERDICT_LABELS` (0 = says string stable).
    prop1 : dict of str to ndarray of bool
        Proposition 1 alone (without Hurwitz) for ``taylor`` and ``printed``.
    sup_gain, margin : ndarray of float or None
        ‖Γ‖_{H∞} and min_ω g(ω) from the exact certificate (when evaluated).
    version : str
        ``stringstab.__version__`` of the tool that computed the map.
    """

    axes: dict[str, Array]
    fixed: dict[str, float]
    params: Params
    methods: tuple[str, ...]
    hurwitz: npt.NDArray[np.bool_]
    type: npt.NDArray[np.int8]
    verdict: dict[str, npt.NDArray[np.int8]]
    prop1: dict[str, npt.NDArray[np.bool_]] = field(default_factory=dict)
    type_printed: npt.NDArray[np.int8] | None = None
    sup_gain: Array | None = None
    margin: Array | None = None
    version: str = ""

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
        """Where ``method`` says string stable (certified, or Hurwitz ∧ Proposition 1)."""
        self._check_method(method)
        return np.asarray(self.verdict[method] == _STABLE)

    def class_names(self, method: str) -> tuple[str, ...]:
        """Names of the class codes of :meth:`classes` for ``method``."""
        self._check_method(method)
        return EXACT_CLASSES if method == "exact" else TYPE_CLASSES

    def classes(self, method: str) -> npt.NDArray[np.int8]:
        """Class code of every point for the class map of ``method``.

        ``exact``: 0 not internally stable, 1 not certified, 2 inconclusive,
        3 certified (:data:`EXACT_CLASSES`).  ``taylor`` / ``printed``: 0 not
        internally stable, then 1 type III, 2 type IV, 3 type I, 4 type II of
        that method's Ψ (:data:`TYPE_CLASSES`).
        """
        self._check_method(method)
        if method == "exact":
            v = self.verdict["exact"]
            c = np.full(self.shape, 3, dtype=np.int8)
            c[v == _UNSTABLE] = 1
            c[(v == _UNSTABLE) & ~self.hurwitz] = 0
            c[v == _INCONCLUSIVE] = 2
            return c
        t = self.type if method == "taylor" else self.type_printed
        assert t is not None
        c = _TYPE_TO_CLASS[t]
        return np.where(self.hurwitz, c, np.int8(0)).astype(np.int8)

    def class_shares(self) -> dict[str, dict[str, float]]:
        """Share of grid points in each class of each method's class map.

        Examples
        --------
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
                      if m == "exact" or lab != "inconclusive"}
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
            decided &= self.verdict[m] != _INCONCLUSIVE
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

        Examples
        --------
        >>> m = region_map({"k_x": np.linspace(-1, 1, 5), "k_v": np.linspace(-1, 1, 5)},
        ...                {"k_a": 0.5}, tau=0.1, delta=0.2, headway=1.1, methods="taylor")
        >>> print(m.report())
        5 x 5 = 25 points: k_x in [-1, 1], k_v in [-1, 1]; k_a = 0.5; τ = 0.1 s, δ = 0.2 s, T* = 1.1 s
        taylor: not internally stable 72.0 %, type III 8.0 %, type IV 0.0 %, type I 20.0 %, type II 0.0 % (stable 20.0 %)
        """
        def pct(x: float) -> str:
            return "<0.1 %" if 0 < x < 1e-3 else f"{100 * x:.1f} %"

        axes = ", ".join(f"{n} in [{a[0]:g}, {a[-1]:g}]" for n, a in self.axes.items())
        lines = [f"{' x '.join(str(s) for s in self.shape)} = {self.size:,} points: {axes}; {self.title()}"]
        width = max(len(m) for m in self.methods)
        vs = self.verdict_shares()
        for m, shares in self.class_shares().items():
            text = ", ".join(f"{k} {pct(v)}" for k, v in shares.items())
            if m != "exact":
                text += f" (stable {pct(vs[m]['stable'])})"
            lines.append(f"{m + ':':<{width + 1}} {text}")
        if len(self.methods) > 1:
            d = self.disagreements()
            pairs = ", ".join(f"{k} {v:,}" for k, v in d.items() if " vs " in k)
            lines.append(f"disagreements: {pairs}; any {d['any']:,} of {self.size:,} points"
                         + (f"; exact inconclusive at {d['inconclusive']:,}" if "exact" in self.methods else ""))
        return "\n".join(lines)

    def title(self) -> str:
        """A one-line description: the fixed gain and the parameters."""
        parts = [f"{k} = {v:g}" for k, v in self.fixed.items()]
        p = self.params
        parts.append(f"τ = {p.tau:g} s, δ = {p.delta:g} s, T* = {p.headway:g} s")
        return "; ".join(parts)

    # ---------------------------------------------------------------- slicing
    def slice(self, gain: str, value: float) -> RegionMap:
        """The 2-D slice of a 3-D map at the grid coordinate of ``gain`` nearest ``value``.

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
            margin=take(self.margin), version=self.version,
        )

    # ---------------------------------------------------------------- files
    def metadata(self) -> dict[str, Any]:
        """Parameters, axes, methods, code tables and the tool version (for files)."""
        return {
            "format": _FORMAT,
            "stringstab_version": self.version,
            "params": self.params.as_dict(),
            "axes": {n: {"min": float(a[0]), "max": float(a[-1]), "n": int(a.size)}
                     for n, a in self.axes.items()},
            "fixed": dict(self.fixed),
            "methods": list(self.methods),
            "verdict_labels": {m: list(VERDICT_LABELS[m]) for m in self.methods},
            "type_names": {str(k): v for k, v in TYPE_NAMES.items()},
        }

    def _fields(self) -> dict[str, np.ndarray]:
        f: dict[str, np.ndarray] = {"hurwitz": self.hurwitz, "type": self.type}
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

    def save_npz(self, path: str | os.PathLike[str]) -> Path:
        """Write the map to a compressed NPZ file with its metadata.

        The archive holds ``axis_<gain>`` coordinates, one array per field
        (``hurwitz``, ``type``, ``verdict_<method>``, ...) and ``metadata``, a
        JSON string with the parameters and the tool version.  Read it back with
        :func:`load_npz`.
        """
        path = Path(path)
        arrays = {f"axis_{n}": a for n, a in self.axes.items()}
        arrays.update(self._fields())
        arrays["metadata"] = np.array(json.dumps(self.metadata()))
        with open(path, "wb") as fh:
            np.savez_compressed(fh, **arrays)  # type: ignore[arg-type]
        return path

    def save_csv(self, path: str | os.PathLike[str]) -> Path:
        """Write one CSV row per grid point, after ``#`` lines with the metadata.

        Columns: ``k_x, k_v, k_a, hurwitz, type`` (I-IV), ``type_printed``,
        one verdict column per method (its labels), ``sup_gain``, ``margin``
        (when evaluated).  The first line is ``# stringstab <version> region
        map``, the second ``# `` followed by :meth:`metadata` as JSON.
        """
        path = Path(path)
        kx, kv, ka = (g.ravel() for g in self.gains())
        cols: list[tuple[str, list[str]]] = [
            ("k_x", [repr(float(v)) for v in kx]),
            ("k_v", [repr(float(v)) for v in kv]),
            ("k_a", [repr(float(v)) for v in ka]),
            ("hurwitz", np.where(self.hurwitz.ravel(), "true", "false").tolist()),
        ]
        names = np.array(["", *TYPE_NAMES.values()])
        cols.append(("type", names[self.type.ravel()].tolist()))
        if self.type_printed is not None:
            cols.append(("type_printed", names[self.type_printed.ravel()].tolist()))
        for m in self.methods:
            cols.append((m, np.array(VERDICT_LABELS[m])[self.verdict[m].ravel()].tolist()))
        if self.sup_gain is not None:
            cols.append(("sup_gain", [repr(float(v)) for v in self.sup_gain.ravel()]))
        if self.margin is not None:
            cols.append(("margin", [repr(float(v)) for v in self.margin.ravel()]))
        with open(path, "w", newline="", encoding="utf-8") as fh:
            fh.write(f"# stringstab {self.version} region map\n")
            fh.write("# " + json.dumps(self.metadata(), ensure_ascii=False) + "\n")
            w = csv.writer(fh, lineterminator="\n")
            w.writerow([c for c, _ in cols])
            w.writerows(zip(*(v for _, v in cols)))
        return path


def load_npz(path: str | os.PathLike[str]) -> RegionMap:
    """Read a map written by :meth:`RegionMap.save_npz`.

    Raises
    ------
    StringStabError
        If the file is not a stringstab region map.
    """
    try:
        with np.load(path, allow_pickle=False) as z:
            data = {k: z[k] for k in z.files}
    except (OSError, ValueError) as e:
        raise StringStabError(f"{path}: expected a region-map NPZ file; could not read it ({e})") from e
    if "metadata" not in data:
        raise StringStabError(f"{path}: expected a region-map NPZ with a 'metadata' entry; found {sorted(data)}")
    meta = json.loads(str(data["metadata"]))
    if meta.get("format") != _FORMAT:
        raise StringStabError(f"{path}: expected format {_FORMAT!r}; found {meta.get('format')!r}")
    methods = tuple(meta["methods"])
    return RegionMap(
        axes={n: data[f"axis_{n}"] for n in meta["axes"]},
        fixed={k: float(v) for k, v in meta["fixed"].items()},
        params=Params(**meta["params"]), methods=methods,
        hurwitz=data["hurwitz"], type=data["type"],
        verdict={m: data[f"verdict_{m}"] for m in methods},
        prop1={m: data[f"prop1_{m}"] for m in methods if f"prop1_{m}" in data},
        type_printed=data.get("type_printed"), sup_gain=data.get("sup_gain"),
        margin=data.get("margin"), version=meta["stringstab_version"],
    )


# --------------------------------------------------------------------------- validation
def _check_axes(
    axes: Mapping[str, npt.ArrayLike], fixed: Mapping[str, float] | None
) -> tuple[dict[str, Array], dict[str, float]]:
    if not isinstance(axes, Mapping):
        raise StringStabError(
            f"axes must map gain names to grid coordinates, e.g. {{'k_x': [...], 'k_v': [...]}}; "
            f"got {type(axes).__name__}"
        )
    names = list(axes)
    for n in names:
        if n not in GAIN_NAMES:
            raise StringStabError(f"axis gains must be among {list(GAIN_NAMES)}; got {n!r}")
    if len(names) not in (2, 3):
        raise StringStabError(f"expected 2 or 3 axis gains; got {len(names)}: {names}")
    out: dict[str, Array] = {}
    for n in names:
        try:
            a = np.asarray(axes[n], dtype=float)
        except (TypeError, ValueError) as e:
            raise StringStabError(f"axis {n} must be numeric grid coordinates; got {axes[n]!r}") from e
        if a.ndim != 1 or a.size < 2:
            raise StringStabError(f"axis {n} must be a 1-D grid of at least 2 points; got shape {a.shape}")
        if not np.all(np.isfinite(a)):
            raise StringStabError(f"axis {n} must be finite; got {a[~np.isfinite(a)][0]!r}")
        if not np.all(np.diff(a) > 0):
            raise StringStabError(f"axis {n} must be strictly increasing; got {a[:5].tolist()}...")
        out[n] = a
    fixed = dict(fixed or {})
    missing = [g for g in GAIN_NAMES if g not in out]
    if len(out) == 3:
        if fixed:
            raise StringStabError(f"a 3-D map fixes no gain; got fixed={fixed}")
        return out, {}
    if list(fixed) != missing:
        raise StringStabError(
            f"a 2-D map over {names} needs the third gain fixed, e.g. fixed={{'{missing[0]}': 0.5}}; "
            f"got fixed={fixed}"
        )
    try:
        v = float(fixed[missing[0]])
    except (TypeError, ValueError) as e:
        raise StringStabError(f"fixed {missing[0]} must be a number; got {fixed[missing[0]]!r}") from e
    if not math.isfinite(v):
        raise StringStabError(f"fixed {missing[0]} must be finite; got {v!r}")
    return out, {missing[0]: v}


def _check_methods(methods: str | Sequence[str]) -> tuple[str, ...]:
    ms = tuple(m.strip() for m in methods.split(",")) if isinstance(methods, str) else tuple(methods)
    if not ms:
        raise StringStabError(f"expected at least one method of {list(METHODS)}; got none")
    for m in ms:
        if m not in METHODS:
            raise StringStabError(f"methods must be among {list(METHODS)}; got {m!r}")
    if len(set(ms)) != len(ms):
        raise StringStabError(f"each method may be given once; got {list(ms)}")
    return ms


# --------------------------------------------------------------------------- entry point
def region_map(
    axes: Mapping[str, npt.ArrayLike],
    fixed: Mapping[str, float] | None = None,
    *,
    tau: float,
    delta: float,
    headway: float,
    methods: str | Sequence[str] = METHODS,
    workers: int | None = None,
    block: int | None = None,
    progress: bool | None = None,
) -> RegionMap:
    """Evaluate every method on a grid of gains (see the module docstring).

    Parameters
    ----------
    axes : mapping of str to array_like
        Two or three of ``"k_x", "k_v", "k_a"``, in axis order, each with
        strictly increasing grid coordinates (at least 2), e.g.
        ``{"k_x": np.linspace(-2, 2, 401), "k_v": np.linspace(-2, 2, 401)}``.
    fixed : mapping of str to float, optional
        For a 2-D map, the value of the third gain, e.g. ``{"k_a": 0.5}``.
    tau, delta, headway : float
        Actuator lag τ > 0, delay δ ≥ 0 and desired headway T* ≥ 0 (seconds).
    methods : str or sequence of str
        Subset of ``("exact", "taylor", "printed")`` (or ``"exact,taylor"``).
        The derived types are always computed.
    workers : int, optional
        Worker processes.  Default: all available cores, or 1 when the map is
        estimated to take under half a second.  ``1`` runs in this process.
    block : int, optional
        Grid points per block (bounds the working memory); default 16 384 with
        ``exact``, 2¹⁹ otherwise.
    progress : bool, optional
        tqdm progress bar on standard error; default: on for maps estimated to
        take more than 5 s.

    Returns
    -------
    RegionMap

    Raises
    ------
    StringStabError
        On bad axes, a missing or extra fixed gain, unknown methods or
        parameters out of range.

    Examples
    --------
    The triple K = (0.9, −0.5, 1.1) is not string stable, yet the printed
    Proposition 1 accepts it:

    >>> m = region_map({"k_x": [0.9, 1.3], "k_v": [-0.5, 0.0]}, {"k_a": 1.1},
    ...                tau=0.1, delta=0.2, headway=1.1)
    >>> m.shape
    (2, 2)
    >>> m.stable("exact").tolist(), m.stable("printed").tolist()
    ([[False, False], [False, False]], [[True, False], [True, False]])
    >>> m.disagreements()["exact vs printed"]
    2
    """
    from ._version import __version__

    p = Params(tau, delta, headway)
    coords, fixed_ = _check_axes(axes, fixed)
    ms = _check_methods(methods)
    names = tuple(coords) + tuple(fixed_)
    internal = tuple(coords.values()) + tuple(np.array([v]) for v in fixed_.values())
    n0, n1, n2 = (a.size for a in internal)
    n = n0 * n1 * n2
    exact = "exact" in ms
    target = int(block) if block is not None else (EXACT_BLOCK if exact else TAYLOR_BLOCK)
    if target < 1:
        raise StringStabError(f"block must be >= 1 grid points; got {block!r}")
    blocks = _blocks(n0, n1, n2, target)
    seconds = n * (_EXACT_SECONDS_PER_POINT if exact else 0.0) + n * _TAYLOR_SECONDS_PER_POINT
    if workers is None:
        workers = 1 if seconds < _PARALLEL_SECONDS else _cpu_count()
    if int(workers) < 1:
        raise StringStabError(f"workers must be >= 1; got {workers!r}")
    workers = min(int(workers), len(blocks))
    if multiprocessing.current_process().daemon:  # e.g. inside another pool: no children allowed
        workers = 1
    if progress is None:
        progress = seconds / workers > 5.0
    spec = _Spec(names, internal, p, ms)  # type: ignore[arg-type]

    shape3 = (n0, n1, n2)
    res: dict[str, np.ndarray] = {
        "hurwitz": np.empty(shape3, dtype=bool),
        "type": np.empty(shape3, dtype=np.int8),
    }
    if "printed" in ms:
        res["type_printed"] = np.empty(shape3, dtype=np.int8)
    for m in ms:
        res[f"verdict_{m}"] = np.empty(shape3, dtype=np.int8)
        if m != "exact":
            res[f"prop1_{m}"] = np.empty(shape3, dtype=bool)
    if exact:
        res["sup_gain"] = np.empty(shape3)
        res["margin"] = np.empty(shape3)

    bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=n, desc="region map", unit="pt", unit_scale=True, file=sys.stderr)
    try:
        for (i0, i1, j0, j1), out in _run_blocks(spec, blocks, workers):
            for k, v in out.items():
                res[k][i0:i1, j0:j1] = v
            if bar is not None:
                bar.update((i1 - i0) * (j1 - j0) * n2)
    finally:
        if bar is not None:
            bar.close()

    grid_shape = tuple(a.size for a in coords.values())

    def get(key: str) -> Any:
        return res[key].reshape(grid_shape) if key in res else None

    return RegionMap(
        axes=coords, fixed=fixed_, params=p, methods=ms,
        hurwitz=get("hurwitz"), type=get("type"),
        verdict={m: get(f"verdict_{m}") for m in ms},
        prop1={m: get(f"prop1_{m}") for m in ms if m != "exact"},
        type_printed=get("type_printed"), sup_gain=get("sup_gain"), margin=get("margin"),
        version=__version__,
    )


def _run_blocks(
    spec: _Spec, blocks: list[tuple[int, int, int, int]], workers: int
) -> Iterator[tuple[tuple[int, int, int, int], dict[str, Any]]]:
    """Evaluate blocks in this process or in ``workers`` processes, yielding as they finish.

    At most ``2 * workers`` blocks are in flight, so memory stays bounded.
    """
    if workers <= 1:
        for b in blocks:
            yield b, _eval_block(spec, *b)
        return
    _warm(spec.methods, spec.names)  # forked workers inherit the lambdified functions
    methods = multiprocessing.get_all_start_methods()
    ctx = multiprocessing.get_context("fork" if "fork" in methods else None)
    with cf.ProcessPoolExecutor(
        max_workers=workers, mp_context=ctx, initializer=_warm, initargs=(spec.methods, spec.names)
    ) as ex:
        pending: dict[cf.Future[dict[str, Any]], tuple[int, int, int, int]] = {}
        it = iter(blocks)
        for b in it:
            pending[ex.submit(_eval_block, spec, *b)] = b
            if len(pending) >= 2 * workers:
                break
        while pending:
            done, _ = cf.wait(pending, return_when=cf.FIRST_COMPLETED)
            for fut in done:
                b = pending.pop(fut)
                yield b, fut.result()
                nxt = next(it, None)
                if nxt is not None:
                    pending[ex.submit(_eval_block, spec, *nxt)] = nxt
