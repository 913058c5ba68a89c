"""Evaluating a region map: the grid, its blocks, and every method on each block.

:func:`region_map` checks the axes and methods, splits the grid into blocks (memory bounded
by the block size), evaluates each (:func:`stringstab.regions.pool.run_blocks`, in this
process or a pool of workers) and assembles a :class:`~stringstab.regions.RegionMap`.  On a
block, the Taylor quantities are evaluated as polynomials in one gain with coefficients on
the plane of the other two (Horner's rule, coefficients generated from the SymPy expressions,
:func:`stringstab.derive.generated.psi_polynomials`), the exact verdicts by
:func:`stringstab.certify.api.certify_batch` — of the continuous loop, of the sampled-data loop
(``sample_time``) or over a box of parameters (intervals), with the continuous certificate
beside a sampled one as the ``continuous`` method.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from ..certify.criteria import hurwitz, proposition1, stability_type
from ..certify.verdicts import codes
from ..derive import generated as _gen
from ..errors import StringStabError
from ..parallel import cpu_count, in_daemon
from ..params import Box, Params, parameter_model
from ..params import sample_time as _sample_time
from .codes import CONTINUOUS, GAIN_NAMES, METHODS, STABLE, UNSTABLE
from .pool import run_blocks
from .result import RegionMap

__all__ = ["EXACT_BLOCK", "TAYLOR_BLOCK", "region_map"]

Array = npt.NDArray[np.float64]

#: Grid points per block: with the exact certificate, and with the Taylor criteria only.
EXACT_BLOCK = 16_384
TAYLOR_BLOCK = 1 << 19
#: Maps estimated to take less than this many seconds run in one process.
_PARALLEL_SECONDS = 0.5
_EXACT_SECONDS_PER_POINT = 2e-5
_TAYLOR_SECONDS_PER_POINT = 1.5e-7
#: Cost of the other certificates relative to the continuous one (analysis/bench_certify.py).
_COST = {(False, False): 1.0, (True, False): 4.0, (False, True): 3.0, (True, True): 400.0}
#: ... times this with a reaction delay θ_r > 0 (certify_batch on a 41³ grid of [−2, 2]³ at
#: τ = 0.1, δ = 0.2, T* = 1.1 s: 2.4e-4 s per triple at θ_r = 0.2 s vs 5.7e-5 at θ_r = 0).
_REACTION_COST = 4.0
#: ... and with a sample time, the sampled θ_r certificate instead (docs/sampled.md §10.4: 3.8-6.6
#: ms per triple at H = 0.1 s; about 250 continuous triples' 2e-5 s).
_SAMPLED_REACTION_COST = 250.0


# --------------------------------------------------------------------------- Taylor on a grid
def _psi_grid(
    source: str, names: tuple[str, str, str], x0: Array, x1: Array, x2: Array, p: Params
) -> tuple[Array, Array, Array, Array]:
    """Ψ1, Ψ2, Ψ3, Λ on the grid x0 × x1 × x2 (shape (n0, n1, n2)), by Horner in x0.

    The coefficients of each Ψ as a polynomial in the gain ``names[0]`` are generated
    from the SymPy expressions (:func:`stringstab.derive.generated.psi_polynomials`).
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
    params: Params | Box
    methods: tuple[str, ...]
    sample_time: float | None = None
    heterogeneous: bool = True
    message_period: float | None = None  # the multi-rate loop (issue 26)

    @property
    def continuous_point(self) -> bool:
        """The continuous loop at one τ, δ, T* without reaction delay (the Taylor criteria apply)."""
        return (self.sample_time is None and isinstance(self.params, Params)
                and not self.params.reaction_delay)


def _reaction(p: Params | Box) -> Any:
    """θ_r of a point, or of a box: its interval (the θ_r box certificate, issue 25 item 4)."""
    return p.reaction_delay


def _eval_certificates(spec: _Spec, full: list[Array], shape: tuple[int, int, int]) -> dict[str, Any]:
    """A sampled or robust block: ``exact`` (and ``continuous``) with their stability."""
    from ..certify.api import certify_batch

    p = spec.params
    out: dict[str, Any] = {}
    b = certify_batch(*full, tau=p.tau, delta=p.delta, headway=p.headway,
                      sample_time=spec.sample_time, heterogeneous=spec.heterogeneous,
                      reaction_delay=_reaction(p),
                      message_period=spec.message_period)
    out["hurwitz"] = np.asarray(b.stable).reshape(shape)
    if hasattr(b, "stability"):  # a θ_r box: stability has a third state, undecided
        out["stability_undecided"] = (np.asarray(b.stability) == "undecided").reshape(shape)
    out["verdict_exact"] = codes(b.verdict).reshape(shape)
    out["sup_gain"] = b.sup_gain.reshape(shape)
    out["margin"] = b.margin.reshape(shape)
    if CONTINUOUS in spec.methods:
        # the continuous loop at the same parameters, θ_r included (issue 25 item 3)
        c = certify_batch(*full, tau=p.tau, delta=p.delta, headway=p.headway,
                          reaction_delay=_reaction(p))
        out["verdict_continuous"] = codes(c.verdict).reshape(shape)
        out["hurwitz_continuous"] = np.asarray(c.stable).reshape(shape)
    return out


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
    if not spec.continuous_point:
        full = [np.broadcast_to(gains[g], shape).ravel() for g in GAIN_NAMES]
        return _eval_certificates(spec, full, shape)
    assert isinstance(p, Params)
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
            out[f"verdict_{method}"] = np.where(ok & hz, STABLE, UNSTABLE).astype(np.int8)
    if "exact" in spec.methods:
        from ..certify.api import certify_batch

        full = [np.broadcast_to(gains[g], shape).ravel() for g in GAIN_NAMES]
        b = certify_batch(*full, tau=p.tau, delta=p.delta, headway=p.headway)
        out["verdict_exact"] = codes(b.verdict).reshape(shape)
        out["sup_gain"] = b.sup_gain.reshape(shape)
        out["margin"] = b.margin.reshape(shape)
    return out


def grid_blocks(n0: int, n1: int, n2: int, target: int) -> list[tuple[int, int, int, int]]:
    """Split an (n0, n1, n2) grid into blocks ``[i0:i1, j0:j1, :]`` of about ``target`` points.

    Parameters
    ----------
    n0, n1, n2 : int
        The grid's shape (points along k_x, k_v, k_a).
    target : int
        The wanted number of points per block (a block holds whole k_a lines).

    Returns
    -------
    list of tuple of int
        ``(i0, i1, j0, j1)`` per block, in order; together they cover the grid once.
    """
    row = n1 * n2
    if row <= target:
        step = max(1, target // row)
        return [(i, min(i + step, n0), 0, n1) for i in range(0, n0, step)]
    jstep = max(1, target // n2)
    return [(i, i + 1, j, min(j + jstep, n1)) for i in range(n0) for j in range(0, n1, jstep)]



def _warm(spec: _Spec) -> None:
    """Run the certificate once (imports and caches; forked workers inherit them)."""
    if "exact" in spec.methods:
        from ..certify.api import certify_batch

        p = spec.params
        certify_batch([1.0], [0.5], [0.2], tau=p.tau, delta=p.delta, headway=p.headway,
                      sample_time=spec.sample_time, reaction_delay=_reaction(p),
                      message_period=spec.message_period)


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


def _check_methods(methods: str | Sequence[str] | None, continuous_point: bool,
                   sampled: bool) -> tuple[str, ...]:
    """The methods to evaluate, checked against the loop.

    The Taylor criteria (``taylor``, ``printed``) need the continuous loop at one τ, δ, T*;
    ``continuous`` (the comparison) needs a sampled map; a sampled or robust map must include
    ``exact``.  None means every method at a continuous point, else ``("exact",)``.
    """
    if methods is None:
        return METHODS if continuous_point else ("exact",)
    ms = tuple(m.strip() for m in methods.split(",")) if isinstance(methods, str) else tuple(methods)
    allowed = METHODS if continuous_point else ("exact", CONTINUOUS) if sampled else ("exact",)
    if not ms:
        raise StringStabError(f"expected at least one method of {list(allowed)}; got none")
    for m in ms:
        if m not in allowed:
            if m in (*METHODS, CONTINUOUS):
                why = ("the Taylor criteria are for the continuous loop at one τ, δ, T* "
                       "without reaction delay"
                       if m in METHODS else "'continuous' compares a sampled map with the "
                       "continuous loop (it needs sample_time)")
                raise StringStabError(f"methods must be among {list(allowed)} here ({why}); got {m!r}")
            raise StringStabError(f"methods must be among {list(allowed)}; got {m!r}")
    if len(set(ms)) != len(ms):
        raise StringStabError(f"each method may be given once; got {list(ms)}")
    if "exact" not in ms and not continuous_point:
        raise StringStabError(f"a sampled or robust map evaluates 'exact'; got methods {list(ms)}")
    return ms



# --------------------------------------------------------------------------- entry point
def region_map(
    axes: Mapping[str, npt.ArrayLike],
    fixed: Mapping[str, float] | None = None,
    *,
    tau: Any,
    delta: Any,
    headway: Any,
    sample_time: float | None = None,
    methods: str | Sequence[str] | None = None,
    workers: int | None = None,
    block: int | None = None,
    progress: bool | None = None,
    heterogeneous: bool = True,
    executor: Any = None,
    message_period: float | None = None,
    reaction_delay: Any = 0.0,
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
    tau, delta, headway : float, (lo, hi) or "LO:HI"
        Actuator lag τ > 0, delay δ ≥ 0 and desired headway T* ≥ 0 (seconds); an interval
        maps the gains certified for every member of the box (the robust certificate).
    sample_time : float, optional
        H > 0 (s): ``exact`` is the sampled-data certificate (zero-order hold).
    methods : str or sequence of str, optional
        For the continuous loop at one τ, δ, T*: a subset of ``("exact", "taylor",
        "printed")`` (or ``"exact,taylor"``), default all three; the derived types are always
        computed.  For a sampled or robust map: ``"exact"`` (the default) and, sampled,
        ``"continuous"`` (the continuous certificate at the same parameters, for the band
        of gains certified in continuous time but not when sampled).
    workers : int, optional
        Worker processes.  Default: all available cores, or 1 when the map is
        estimated to take under half a second.  ``1`` runs in this process.
    block : int, optional
        Grid points per block (bounds the working memory); default 16 384 with
        ``exact``, 2¹⁹ otherwise.
    progress : bool, optional
        Progress on standard error (:class:`stringstab.progress.Progress`: a bar on a
        terminal, plain lines otherwise); default: on for maps estimated to take more than 5 s.
    heterogeneous : bool
        Sampled box only: the predecessor's lag ranges over the τ box independently.
    executor : concurrent.futures.Executor, optional
        Evaluate the blocks there instead of the local pool, ``2 × workers`` in flight (e.g.
        a Dask client's ``get_executor()``: the blocks as tasks of a cluster).  The map is the
        same bit for bit: every block is evaluated by the same function and put in its place.
    message_period : float, optional
        With ``sample_time``: ``exact`` is the multi-rate certificate of V2V messages every
        ``message_period`` s (:mod:`stringstab.certify.multirate`); equal to the sample time,
        the sampled one.
    reaction_delay : float
        θ_r ≥ 0 (s), the reaction delay on the whole command (issue 25): with θ_r > 0,
        ``exact`` is the continuous certificate of :mod:`stringstab.certify.reaction` (the one
        method: the Taylor criteria are of the loop without θ_r; ``hurwitz`` is the proven
        stability of the quasi-polynomial); with ``sample_time``, ``exact`` is the sampled θ_r
        certificate (:mod:`stringstab.certify.sampled_reaction`, docs/sampled.md §10) and
        ``continuous`` the continuous one with the same θ_r; an interval is the θ_r box
        certificate, in continuous time (with a sample time, or what else no certificate
        answers, the certificate's refusal is raised before any work).  θ_r = 0 (the
        default) computes the map it always did, bit for bit.

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
    from .._version import __version__  # the package's one version (a constant, not a layer)

    p = parameter_model(tau, delta, headway, reaction_delay)
    H = None if sample_time is None else _sample_time(sample_time)
    box = isinstance(p, Box)
    P = _message_period(message_period, H, box)
    theta = Box.of(p).reaction_delay != (0.0, 0.0)
    if theta:  # θ_r > 0 (issue 25): refused beyond the continuous point loop, before any work
        from ..certify.api import Loop

        Loop(p, H)
    coords, fixed_ = _check_axes(axes, fixed)
    ms = _check_methods(methods, H is None and not box and not theta, H is not None)
    names = tuple(coords) + tuple(fixed_)
    internal = tuple(coords.values()) + tuple(np.array([v]) for v in fixed_.values())
    n0, n1, n2 = (a.size for a in internal)
    n = n0 * n1 * n2
    exact = "exact" in ms
    target = int(block) if block is not None else (EXACT_BLOCK if exact else TAYLOR_BLOCK)
    if target < 1:
        raise StringStabError(f"block must be >= 1 grid points; got {block!r}")
    blocks = grid_blocks(n0, n1, n2, target)
    cost = (_COST[H is not None, box] * (30.0 if P is not None else 1.0) + (CONTINUOUS in ms)) * (
        _REACTION_COST if theta else 1.0)
    if theta and H is not None:  # the sampled θ_r certificate (issue 25 item 3)
        cost = _SAMPLED_REACTION_COST + (_REACTION_COST if CONTINUOUS in ms else 0.0)
    seconds = n * (_EXACT_SECONDS_PER_POINT * cost if exact else 0.0) + n * _TAYLOR_SECONDS_PER_POINT
    if workers is None:
        workers = 1 if seconds < _PARALLEL_SECONDS and executor is None else cpu_count()
    if int(workers) < 1:
        raise StringStabError(f"workers must be >= 1; got {workers!r}")
    workers = min(int(workers), len(blocks))
    if in_daemon() and executor is None:  # e.g. inside another pool: no children allowed
        workers = 1
    if progress is None:
        progress = seconds / workers > 5.0
    spec = _Spec(names, internal, p, ms, H, bool(heterogeneous), P)  # type: ignore[arg-type]

    shape3 = (n0, n1, n2)
    res: dict[str, np.ndarray] = {"hurwitz": np.empty(shape3, dtype=bool)}
    if spec.continuous_point:
        res["type"] = np.empty(shape3, dtype=np.int8)
    if CONTINUOUS in ms:
        res["hurwitz_continuous"] = np.empty(shape3, dtype=bool)
    if "printed" in ms:
        res["type_printed"] = np.empty(shape3, dtype=np.int8)
    for m in ms:
        res[f"verdict_{m}"] = np.empty(shape3, dtype=np.int8)
        if m in ("taylor", "printed"):
            res[f"prop1_{m}"] = np.empty(shape3, dtype=bool)
    if exact:
        res["sup_gain"] = np.empty(shape3)
        res["margin"] = np.empty(shape3)

    # plain lines off a terminal, a bar without a monitor thread on one (stringstab.progress)
    from ..progress import Progress

    blocks_done = run_blocks(_eval_block, spec, blocks, workers, warm=_warm, executor=executor)
    with Progress(n, "region map", unit="points", enabled=bool(progress)) as bar, \
            contextlib.closing(blocks_done):
        for (i0, i1, j0, j1), out in blocks_done:
            for k, v in out.items():
                if k not in res:  # stability_undecided: θ_r box maps only
                    res[k] = np.zeros(shape3, dtype=np.asarray(v).dtype)
                res[k][i0:i1, j0:j1] = v
            bar.update((i1 - i0) * (j1 - j0) * n2)

    grid_shape = tuple(a.size for a in coords.values())

    def get(key: str) -> Any:
        return res[key].reshape(grid_shape) if key in res else None

    return RegionMap(
        axes=coords, fixed=fixed_, params=p, methods=ms,
        hurwitz=get("hurwitz"), type=get("type"),
        verdict={m: get(f"verdict_{m}") for m in ms},
        prop1={m: get(f"prop1_{m}") for m in ms if m in ("taylor", "printed")},
        type_printed=get("type_printed"), sup_gain=get("sup_gain"), margin=get("margin"),
        version=__version__, sample_time=H, heterogeneous=bool(heterogeneous),
        hurwitz_continuous=get("hurwitz_continuous"), message_period=P,
        stability_undecided=get("stability_undecided"),
    )


def _message_period(message_period: Any, H: float | None, box: bool) -> float | None:
    """The multi-rate map's message period N·H, checked; None for N = 1 (the sampled map)."""
    if message_period is None:
        return None
    if H is None:
        raise StringStabError("message_period (the V2V message period) needs the control "
                              "period: expected sample_time with it, got none")
    from ..certify.message import message_steps

    N = message_steps(message_period, H)
    if N < 2:
        return None
    if box:
        raise StringStabError("the multi-rate certificate is for one τ, δ, T*; got a parameter "
                              "box with message_period (not supported)")
    return round(N * H, 12)
