"""Lead-vehicle trajectories by name.

:func:`leader_by_name` turns a command-line spec into a
:class:`~stringstab.traffic.trajectory.Trajectory`: a bundled driving cycle
(:mod:`~stringstab.traffic.cycles`), a synthetic profile with parameters
(:mod:`~stringstab.traffic.synthetic`) or a ``t, v[, a]`` CSV file
(:mod:`~stringstab.traffic.loaders`).  The leader API itself lives in those modules and in
:mod:`~stringstab.traffic.trajectory` and :mod:`~stringstab.traffic.split`; the package
:mod:`stringstab.traffic` exports its public names.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ..constants import DT
from ..errors import StringStabError, show
from .cycles import CYCLE_ALIASES, CYCLES, cycle
from .loaders import load_csv
from .synthetic import (
    SYNTHETIC,
)
from .trajectory import Trajectory

__all__ = ["leader_by_name"]


def _parse_kwargs(spec: str, fn: Callable[..., Any], what: str) -> dict[str, Any]:
    accepted = [p for p in inspect.signature(fn).parameters if p != "dt"]
    out: dict[str, Any] = {}
    for item in filter(None, (s.strip() for s in spec.split(","))):
        key, sep, val = item.partition("=")
        key = key.strip()
        if not sep or key not in accepted:
            raise StringStabError(
                f"{what}: expected KEY=VALUE with KEY in {accepted}; got {show(item)}"
            )
        try:
            num = float(val)
        except ValueError as e:
            raise StringStabError(f"{what}: {key} must be a number; got {show(val.strip())}") from e
        out[key] = int(num) if key == "waves" else num
    return out


def leader_by_name(spec: str, *, dt: float = DT, duration: float | None = None) -> Trajectory:
    """The leader named by a command-line spec.

    ``spec`` is a cycle name (``udds``, ``hwfet``, ``us06``, ``wltc3b``), a synthetic profile
    with optional parameters (``sinusoid:omega=0.5,amplitude=1``, ``braking``,
    ``acceleration``, ``stop-and-go:waves=2``, ``mix``) or the path of a ``t, v[, a]`` CSV file.

    Parameters
    ----------
    spec : str
        See above.
    dt : float
        Step, s.
    duration : float, optional
        Keep only the first ``duration`` seconds.

    Returns
    -------
    Trajectory
        The leader's speed profile.

    Raises
    ------
    StringStabError
        For an unknown name, a bad parameter or an unreadable file.

    Examples
    --------
    >>> leader_by_name("sinusoid:omega=0.5", dt=0.1).meta["omega"]
    0.5
    >>> leader_by_name("nope")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: unknown leader 'nope'; expected a cycle ...
    """
    name, _, params = str(spec).partition(":")
    key = name.strip().lower()
    if key in SYNTHETIC:
        fn = SYNTHETIC[key]
        kwargs = _parse_kwargs(params, fn, f"leader {show(key)}")
        missing = [p.name for p in inspect.signature(fn).parameters.values()
                   if p.default is p.empty and p.name not in kwargs]
        if missing:
            raise StringStabError(
                f"leader {show(key)} needs {', '.join(missing)}: expected "
                f"{key}:{'=...,'.join(missing)}=... (e.g. {key}:omega=0.5); got {show(spec)}"
            )
        tr = fn(dt=dt, **kwargs)
    elif key in CYCLES or key in CYCLE_ALIASES:
        if params:
            raise StringStabError(f"leader {show(key)} takes no parameters; got {show(params)}")
        tr = cycle(key, dt=dt)
    elif spec.lower().endswith((".csv", ".csv.gz")) or Path(spec).is_file():
        tr = load_csv(spec, dt=dt)
    else:
        raise StringStabError(
            f"unknown leader {show(spec)}; expected a cycle {sorted(CYCLES)}, a synthetic profile "
            f"{sorted(SYNTHETIC)} (NAME:key=value,...) or the path of a 't, v[, a]' CSV file"
        )
    return tr if duration is None else tr.head(duration)
