"""A sweep spec: a TOML file naming a job, its base settings, the axes to vary and the seeds.

Layout (every table but ``[sweep]`` optional)::

    [sweep]
    name = "table3-reduced"   # a label for the outputs
    kind = "train"            # train | region | certify | probe (what each point computes)
    study = "table3"          # none | table3 | table5 | fig4 | fig5 | certificate (the report)
    seeds = [0, 1]            # crossed with every point (train and probe only)

    [base]                    # settings shared by every point (the kind's fields)
    algo = "idl"
    total_steps = 20000

    [axes]                    # crossed: every combination
    exploration_noise = {start = 0.05, stop = 0.30, step = 0.05}

    [zip]                     # zipped: the i-th values together (equal lengths), crossed with [axes]
    label = ["Tradeoff", "Mild safety bias"]
    weights = [[0.3333, 0.3333, 0.3333], [0.4, 0.3, 0.3]]

An axis is a non-empty list of values or a range ``{start, stop, step}`` (``stop`` included
when it falls on the step) or ``{start, stop, num}`` (``num`` evenly spaced values, both ends
included).  ``label`` names a point in the reports and is not part of its settings.

Fields of each kind (:data:`KIND_FIELDS`):

``train``
    every :class:`stringstab.rl.TD3Config` / :class:`~stringstab.rl.DDPGConfig` field
    (``weights`` are the reward weights ω1, ω2, ω3 of IDL eq 18, ``repair`` the repair mode),
    plus ``algo`` (``idl``, ``td3``, ``ddpg``: :func:`stringstab.rl.config_for`) and ``paper``
    (IDL as printed).  The point trains (:func:`stringstab.rl.train`) and evaluates the policy
    on the bundled test episodes (:func:`stringstab.rl.evaluate.evaluate`).
``region``
    a region map (:func:`stringstab.regions.region_map`): ``x``, ``y``, ``fix`` (``"k_a=0.5"``;
    absent: a 3-D map), ``range`` ([lo, hi]), ``n``, ``tau``, ``delta``, ``headway`` (a number
    or an interval ``"lo:hi"``), ``sample_time``, ``methods``.
``certify``
    the certified share of a 3-D gain grid (the sampled/robust findings): ``range``, ``n``,
    ``tau``, ``delta``, ``headway``, ``sample_time``; with a sample time or an interval, the
    continuous-time certificate at the nominal parameters is evaluated beside it.
``probe``
    checks a cluster and measures its overhead: sleeps ``seconds``, then fails if ``fail``.

Every point is resolved and checked when the spec is loaded (:func:`load_spec`): an unknown
table or field, a bad value or an empty axis is refused with the field's name and what is
allowed, before anything runs.  A point's id is a hash of its kind and resolved settings
(:attr:`Point.id`), so it is the same in every run of any spec that contains it.
"""

from __future__ import annotations

import dataclasses
import hashlib
import itertools
import json
import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import tomllib

from ..errors import StringStabError, show

__all__ = ["KINDS", "KIND_FIELDS", "STUDIES", "Point", "SweepSpec", "expand_axis", "load_spec",
           "parse_spec"]

#: What a point computes.
KINDS = ("train", "region", "certify", "probe")
#: The report drawn from the table of all points (:mod:`stringstab.sweep.report`).
STUDIES = ("none", "table3", "table5", "fig4", "fig5", "certificate")

_GEOMETRY = ("tau", "delta", "headway", "sample_time")
#: Fields of each kind besides the TD3Config fields of ``train``.
KIND_FIELDS: dict[str, tuple[str, ...]] = {
    "train": ("algo", "paper"),
    "region": ("x", "y", "fix", "range", "n", "methods", *_GEOMETRY),
    "certify": ("range", "n", *_GEOMETRY),
    "probe": ("seconds", "fail", "seed"),
}
_DEFAULTS: dict[str, dict[str, Any]] = {
    "region": {"x": "k_x", "y": "k_v", "fix": None, "range": [-2.0, 2.0], "n": 41,
               "methods": None, "tau": 0.1, "delta": 0.2, "headway": 1.1, "sample_time": None},
    "certify": {"range": [-2.0, 2.0], "n": 21, "tau": 0.1, "delta": 0.2, "headway": 1.1,
                "sample_time": None},
    "probe": {"seconds": 0.0, "fail": False, "seed": 0},
}


def _train_fields() -> tuple[str, ...]:
    from ..rl.config import DDPGConfig

    return tuple(f.name for f in dataclasses.fields(DDPGConfig))


def allowed_fields(kind: str) -> tuple[str, ...]:
    """The fields a point of ``kind`` accepts (``label`` aside).

    Parameters
    ----------
    kind : str
        One of :data:`KINDS`.

    Returns
    -------
    tuple of str
    """
    if kind == "train":
        return tuple(dict.fromkeys((*KIND_FIELDS["train"], *_train_fields())))
    return KIND_FIELDS[kind]


@dataclass(frozen=True)
class Point:
    """One point of a sweep: its kind, resolved settings, label and stable id.

    ``settings`` are plain JSON values: for ``train`` the whole config
    (:meth:`stringstab.rl.TD3Config.as_dict`, every default filled in), for the other kinds
    every field with its default.
    """

    kind: str
    settings: dict[str, Any]
    label: str = ""
    varied: dict[str, Any] = field(default_factory=dict)

    @property
    def id(self) -> str:
        """12 hex digits of the SHA-256 of the kind and the resolved settings (canonical JSON)."""
        text = json.dumps({"kind": self.kind, "settings": self.settings}, sort_keys=True,
                          separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()[:12]

    def as_dict(self) -> dict[str, Any]:
        """The point as JSON values (what a task receives)."""
        return {"id": self.id, "kind": self.kind, "label": self.label, "varied": self.varied,
                "settings": self.settings}


@dataclass(frozen=True)
class SweepSpec:
    """A loaded, checked sweep spec (:func:`load_spec`)."""

    name: str
    kind: str
    study: str
    points: tuple[Point, ...]
    source: str = ""
    text: str = ""

    def __len__(self) -> int:
        return len(self.points)


# --------------------------------------------------------------------------- axes
def expand_axis(name: str, value: Any) -> list[Any]:
    """The values of axis ``name``: a non-empty list, or a range table.

    Parameters
    ----------
    name : str
        The field the axis varies (for the error messages).
    value : list or dict
        A non-empty list, ``{start, stop, step}`` (``stop`` included when it falls on a step;
        a tolerance of 1e-9 steps) or ``{start, stop, num}`` (evenly spaced, both ends).

    Returns
    -------
    list
        The values; integers when every bound is an integer, else floats rounded to 12
        decimals (so 0.1 + 2 × 0.05 is 0.2, and ids do not depend on round-off).

    Raises
    ------
    StringStabError
        For an empty list, an unknown range key, a non-finite bound or a step of the wrong sign.

    Examples
    --------
    >>> expand_axis("exploration_noise", {"start": 0.05, "stop": 0.3, "step": 0.05})
    [0.05, 0.1, 0.15, 0.2, 0.25, 0.3]
    >>> expand_axis("seed", {"start": 0, "stop": 4, "num": 3})
    [0, 2, 4]
    >>> expand_axis("tau", [])
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: axis tau is empty; expected a non-empty list or a range {start, stop, step|num}
    """
    if isinstance(value, list):
        if not value:
            raise StringStabError(f"axis {name} is empty; expected a non-empty list or a range "
                                  "{start, stop, step|num}")
        return list(value)
    if not isinstance(value, dict):
        raise StringStabError(f"axis {name}: expected a list of values or a range "
                              f"{{start, stop, step|num}}; got {show(value)}")
    keys = set(value)
    if not ({"start", "stop"} <= keys and len(keys & {"step", "num"}) == 1
            and keys <= {"start", "stop", "step", "num"}):
        raise StringStabError(f"axis {name}: a range needs start, stop and one of step, num; "
                              f"got keys {sorted(keys)}")
    nums = {k: v for k, v in value.items()}
    for k, v in nums.items():
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise StringStabError(f"axis {name}: range {k} must be a finite number; got {show(v)}")
    start, stop = nums["start"], nums["stop"]
    ints = all(isinstance(v, int) for v in nums.values())
    if "num" in nums:
        num = nums["num"]
        if not isinstance(num, int) or num < 1:
            raise StringStabError(f"axis {name}: range num must be an integer >= 1; got {show(num)}")
        if num == 1:
            vals = [start]
        else:
            vals = [start + (stop - start) * i / (num - 1) for i in range(num)]
    else:
        step = nums["step"]
        if step == 0 or (stop - start) * step < 0:
            raise StringStabError(f"axis {name}: range step {show(step)} does not lead from "
                                  f"{show(start)} to {show(stop)}")
        count = math.floor((stop - start) / step + 1e-9) + 1
        vals = [start + i * step for i in range(count)]
    if ints and all(float(v).is_integer() for v in vals):
        return [int(v) for v in vals]
    return [round(float(v), 12) for v in vals]


# --------------------------------------------------------------------------- resolving a point
def _plain(v: Any) -> Any:
    if isinstance(v, tuple):
        return [_plain(x) for x in v]
    if isinstance(v, list):
        return [_plain(x) for x in v]
    return v


def _resolve(kind: str, fields: Mapping[str, Any], where: str) -> dict[str, Any]:
    """The resolved settings of one point (checked), as JSON values."""
    if kind == "train":
        from ..rl.config import config_for

        kw = dict(fields)
        algo = kw.pop("algo", "idl")
        paper = kw.pop("paper", False)
        if not isinstance(paper, bool):
            raise StringStabError(f"{where}: field paper must be true or false; got {show(paper)}")
        for key in ("hidden", "weights", "observe", "start_spread"):
            if isinstance(kw.get(key), list):
                kw[key] = tuple(kw[key])
        if "algo" in fields and algo not in ("idl", "td3", "ddpg"):
            raise StringStabError(f"{where}: field algo must be one of idl, td3, ddpg; got {show(algo)}")
        try:
            cfg = config_for(algo, paper=paper, **kw)
        except StringStabError as e:
            raise StringStabError(f"{where}: {e}") from e
        except TypeError as e:  # pragma: no cover - fields are checked before
            raise StringStabError(f"{where}: {e}") from e
        d = cfg.as_dict()
        d["paper"] = paper
        return d
    out = {**_DEFAULTS[kind], **fields}
    if kind == "probe":
        s = out["seconds"]
        if isinstance(s, bool) or not isinstance(s, (int, float)) or not (math.isfinite(s) and s >= 0):
            raise StringStabError(f"{where}: field seconds must be a number >= 0; got {show(s)}")
        if not isinstance(out["fail"], bool):
            raise StringStabError(f"{where}: field fail must be true or false; got {show(out['fail'])}")
        if isinstance(out["seed"], bool) or not isinstance(out["seed"], int):
            raise StringStabError(f"{where}: field seed must be an integer; got {show(out['seed'])}")
        return _plain(out)
    _check_geometry(kind, out, where)
    return _plain(out)


def _check_geometry(kind: str, f: dict[str, Any], where: str) -> None:
    """Check the fields of a region or certify point with the library's own checks."""
    from ..params import parameter_model
    from ..params import sample_time as check_sample_time

    def num_or_interval(name: str) -> None:
        v = f[name]
        if isinstance(v, str):
            return
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise StringStabError(f"{where}: field {name} must be a number or an interval "
                                  f"'lo:hi'; got {show(v)}")

    for name in ("tau", "delta", "headway"):
        num_or_interval(name)
    try:
        parameter_model(f["tau"], f["delta"], f["headway"])
        if f["sample_time"] is not None:
            check_sample_time(f["sample_time"])
    except StringStabError as e:
        raise StringStabError(f"{where}: {e}") from e
    r = f["range"]
    if (not isinstance(r, list) or len(r) != 2 or any(isinstance(x, bool) or not isinstance(x, (int, float))
                                                     for x in r) or not r[0] < r[1]):
        raise StringStabError(f"{where}: field range must be [lo, hi] with lo < hi; got {show(r)}")
    n = f["n"]
    if isinstance(n, bool) or not isinstance(n, int) or n < 2:
        raise StringStabError(f"{where}: field n must be an integer >= 2; got {show(n)}")
    if kind == "region":
        from ..regions import GAIN_NAMES, METHODS

        for name in ("x", "y"):
            if f[name] not in GAIN_NAMES:
                raise StringStabError(f"{where}: field {name} must be one of {list(GAIN_NAMES)}; "
                                      f"got {show(f[name])}")
        if f["x"] == f["y"]:
            raise StringStabError(f"{where}: fields x and y must be different gains; got {f['x']} twice")
        if f["fix"] is not None:
            third = next(g for g in GAIN_NAMES if g not in (f["x"], f["y"]))
            g, sep, v = str(f["fix"]).partition("=")
            try:
                ok = sep and g.strip() == third and math.isfinite(float(v))
            except ValueError:
                ok = False
            if not ok:
                raise StringStabError(f"{where}: field fix must be '{third}=VALUE' (the gain not on "
                                      f"x, y); got {show(f['fix'])}")
        m = f["methods"]
        allowed = (*METHODS, "continuous")
        if m is not None and (not isinstance(m, list) or not m or any(x not in allowed for x in m)):
            raise StringStabError(f"{where}: field methods must be a list among {list(allowed)}; "
                                  f"got {show(m)}")


# --------------------------------------------------------------------------- the spec
_TABLES = ("sweep", "base", "axes", "zip")
_SWEEP_KEYS = ("name", "kind", "study", "seeds")


def parse_spec(text: str, *, source: str = "spec") -> SweepSpec:
    """Parse and check the TOML text of a sweep spec (see the module docstring).

    Parameters
    ----------
    text : str
        The TOML document: ``[sweep]`` (required), ``[base]``, ``[axes]``, ``[zip]``.
    source : str, default "spec"
        Where the text came from (e.g. the file name), as the first words of an error.

    Returns
    -------
    SweepSpec
        The checked spec with its expanded points.

    Raises
    ------
    StringStabError
        On malformed TOML, an unknown table or field, a bad value, an empty axis, zipped axes
        of different lengths, or two points with the same settings.
    """
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise StringStabError(f"{source}: not valid TOML ({e})") from e
    unknown = sorted(set(doc) - set(_TABLES))
    if unknown:
        raise StringStabError(f"{source}: unknown table [{unknown[0]}]; allowed: {', '.join(_TABLES)}")
    for t in _TABLES:
        if t in doc and not isinstance(doc[t], dict):
            raise StringStabError(f"{source}: [{t}] must be a table; got {show(doc[t])}")
    head = doc.get("sweep")
    if head is None:
        raise StringStabError(f"{source}: expected a [sweep] table with kind = one of {list(KINDS)}; found none")
    bad = sorted(set(head) - set(_SWEEP_KEYS))
    if bad:
        raise StringStabError(f"{source}: [sweep] unknown field {bad[0]!r}; allowed: {', '.join(_SWEEP_KEYS)}")
    kind = head.get("kind")
    if kind not in KINDS:
        raise StringStabError(f"{source}: [sweep] field kind must be one of {list(KINDS)}; got {show(kind)}")
    study = head.get("study", "none")
    if study not in STUDIES:
        raise StringStabError(f"{source}: [sweep] field study must be one of {list(STUDIES)}; got {show(study)}")
    name = head.get("name", Path(source).stem)
    if not isinstance(name, str) or not name:
        raise StringStabError(f"{source}: [sweep] field name must be a non-empty string; got {show(name)}")
    allowed = allowed_fields(kind)
    base = dict(doc.get("base", {}))
    try:
        axes = {k: expand_axis(k, v) for k, v in doc.get("axes", {}).items()}
        zipped = {k: expand_axis(k, v) for k, v in doc.get("zip", {}).items()}
    except StringStabError as e:
        raise StringStabError(f"{source}: {e}") from e
    for table, d in (("base", base), ("axes", axes), ("zip", zipped)):
        for k in d:
            if k != "label" and k not in allowed:
                raise StringStabError(f"{source}: [{table}] unknown field {k!r} for kind {kind}; "
                                      f"allowed: {', '.join(allowed)}")
    if "label" in base or "label" in axes:
        raise StringStabError(f"{source}: label names zipped values; put it in [zip]")
    both = sorted((set(base) & set(axes)) | (set(base) & set(zipped)) | (set(axes) & set(zipped)))
    if both:
        raise StringStabError(f"{source}: field {both[0]!r} is set in two tables; give it in one of "
                              "[base], [axes], [zip]")
    lengths = {k: len(v) for k, v in zipped.items()}
    if len(set(lengths.values())) > 1:
        raise StringStabError(f"{source}: [zip] lists must have equal lengths; got {lengths}")
    seeds: list[Any] | None = None
    if "seeds" in head:
        if kind not in ("train", "probe"):
            raise StringStabError(f"{source}: [sweep] seeds apply to kind train or probe; got kind {kind}")
        try:
            seeds = expand_axis("seeds", head["seeds"])
        except StringStabError as e:
            raise StringStabError(f"{source}: [sweep] {e}") from e
        if any(isinstance(s, bool) or not isinstance(s, int) or s < 0 for s in seeds):
            raise StringStabError(f"{source}: [sweep] seeds must be integers >= 0; got {show(seeds)}")
        if "seed" in base or "seed" in axes or "seed" in zipped:
            raise StringStabError(f"{source}: give seeds in [sweep] seeds or a seed field, not both")
    n_zip = next(iter(lengths.values()), 1)
    zip_rows = [{k: v[i] for k, v in zipped.items()} for i in range(n_zip)]
    axis_names = list(axes)
    points: list[Point] = []
    seen: dict[str, str] = {}
    for zrow in zip_rows:
        for combo in itertools.product(*(axes[k] for k in axis_names)):
            for seed in (seeds if seeds is not None else [None]):
                varied = {**zrow, **dict(zip(axis_names, combo))}
                if seed is not None:
                    varied["seed"] = seed
                label = str(varied.pop("label", ""))
                fields = {**base, **varied}
                where = f"{source}: point {_describe(label, varied)}"
                settings = _resolve(kind, fields, where)
                pt = Point(kind, settings, label, _plain(varied))
                if pt.id in seen:
                    raise StringStabError(f"{source}: points {seen[pt.id]} and "
                                          f"{_describe(label, varied)} have the same settings")
                seen[pt.id] = _describe(label, varied)
                points.append(pt)
    return SweepSpec(name=name, kind=kind, study=study, points=tuple(points), source=source,
                     text=text)


def _describe(label: str, varied: Mapping[str, Any]) -> str:
    parts = [label] if label else []
    parts += [f"{k}={show(v)}" for k, v in varied.items()]
    return "(" + ", ".join(parts) + ")" if parts else "(base)"


def load_spec(path: str | os.PathLike[str]) -> SweepSpec:
    """Read and check a sweep spec file (:func:`parse_spec`).

    Parameters
    ----------
    path : path
        A TOML file.

    Returns
    -------
    SweepSpec

    Raises
    ------
    StringStabError
        For a missing or unreadable file, or any error of :func:`parse_spec`.
    """
    from ..io.text_input import read_text

    p = Path(path)
    text = read_text(p, label=f"spec {str(p)!r}", expected="a TOML sweep spec")
    return parse_spec(text, source=str(p))

