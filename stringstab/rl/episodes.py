"""The leaders a policy trains and is tested on: cycle episodes, synthetic disturbances, user files.

The IDL paper trains on 900 NGSIM car-following pairs and tests on 386 others (§4.1.1).  NGSIM
cannot ship with the toolkit, so the default data are the four bundled driving cycles (EPA UDDS,
HWFET, US06, WLTC 3b) cut into episodes of ``seconds`` (30 s by default; NGSIM pairs last at
least 15 s) and split 70/30 into training and test episodes with a fixed seed
(:func:`stringstab.traffic.train_test_split`), plus synthetic disturbances — different ones in
each split (sinusoids, hard braking and acceleration at the Table 2 limits, stop-and-go).
Episodes in which the leader never exceeds 1 m/s are dropped (nothing to learn there).
The §5.1 leader (:func:`stringstab.traffic.paper_mix`) is in neither split: it is kept for the
platoon test.

A user's file replaces the bundled data: a ``t, v[, a]`` CSV (:func:`stringstab.traffic.load_csv`)
is cut into episodes for training and kept whole for testing; an NGSIM file
(:func:`stringstab.traffic.load_ngsim_pairs`) gives leader–follower pairs, split 70/30 with the
same seed (training uses the first part, testing the second).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from pathlib import Path
from typing import Literal

from ..errors import StringStabError
from ..io.text_input import open_text
from ..traffic.cycles import CYCLES, cycle
from ..traffic.loaders import FollowingPair, load_csv, load_ngsim_pairs
from ..traffic.split import train_test_split
from ..traffic.synthetic import hard_acceleration, hard_braking, sinusoid, stop_and_go
from ..traffic.trajectory import Trajectory

__all__ = ["Split", "cut", "default_leaders", "leaders_from_files"]

Split = Literal["train", "test"]
Leader = Trajectory | FollowingPair

#: Test fraction and seed of every split (the paper: 386 of 1286 pairs ≈ 0.3).
TEST_FRACTION, SPLIT_SEED = 0.3, 0
#: Episodes whose leader never exceeds this speed (m/s) are dropped.
MIN_TOP_SPEED = 1.0


def cut(tr: Trajectory, seconds: float) -> list[Trajectory]:
    """Non-overlapping windows of ``seconds`` (the tail shorter than a window is dropped).

    Each window has round(seconds/dt) steps (one more sample), is re-timed to start at
    t = 0 and named ``<name>@<start>s``.

    Parameters
    ----------
    tr : Trajectory
        The leader to cut.
    seconds : float
        Window length, s.

    Returns
    -------
    list of Trajectory
        The windows in order (empty if ``tr`` is shorter than one window).

    Raises
    ------
    StringStabError
        If ``seconds`` is shorter than one step.

    Examples
    --------
    >>> from stringstab.traffic import cycle
    >>> parts = cut(cycle("us06"), 30.0)
    >>> len(parts), parts[0].duration
    (20, 30.0)
    """
    n = round(seconds / tr.dt)
    if n < 1:
        raise StringStabError(f"episode length must be at least one step dt={tr.dt} s; got {seconds!r} s")
    out = []
    for start in range(0, tr.n_steps - n, n):
        w = tr.window(start, start + n + 1)
        out.append(type(w)(w.dt, w.position, w.speed, w.accel, f"{tr.name}@{start * tr.dt:g}s",
                           dict(tr.meta)))
    return out


def _moving(items: Sequence[Trajectory]) -> list[Trajectory]:
    return [tr for tr in items if float(tr.speed.max()) > MIN_TOP_SPEED]


def _synthetic(split: Split, dt: float) -> list[Trajectory]:
    if split == "train":
        return [*(sinusoid(omega=w, amplitude=2.0, speed=15.0, duration=60.0, dt=dt)
                  for w in (0.2, 0.5, 1.0, 2.0)),
                hard_braking(speed=20.0, to_speed=5.0, dt=dt),
                hard_acceleration(speed=5.0, to_speed=20.0, dt=dt),
                stop_and_go(waves=2, dt=dt)]
    test = [*(sinusoid(omega=w, amplitude=3.0, speed=20.0, duration=60.0, dt=dt)
              for w in (0.3, 0.8, 1.5)),
            hard_braking(speed=25.0, to_speed=0.0, dt=dt),
            hard_acceleration(speed=2.0, to_speed=25.0, dt=dt),
            stop_and_go(speed_high=20.0, waves=3, accel=2.5, decel=-3.0, dt=dt)]
    return [dataclasses.replace(tr, name=f"{tr.name}-test") for tr in test]


def default_leaders(split: Split, *, seconds: float = 30.0, dt: float = 0.1) -> list[Trajectory]:
    """The bundled training or test episodes (see the module docstring).

    Parameters
    ----------
    split : {"train", "test"}
        Which split: 70 % or 30 % of the driving-cycle windows (fixed seed), plus that split's
        synthetic disturbances.
    seconds : float
        Episode length, s.
    dt : float
        Sample step, s.

    Returns
    -------
    list of Trajectory
        The cycle windows, then the synthetic ones; leaders that never exceed 1 m/s are
        dropped.

    Raises
    ------
    StringStabError
        If ``split`` is neither ``"train"`` nor ``"test"``.

    Examples
    --------
    >>> train, test = default_leaders("train"), default_leaders("test")
    >>> len(train) > len(test) > 0, {tr.n_steps for tr in train + test}
    (True, {301})
    >>> not {tr.name for tr in train} & {tr.name for tr in test}
    True
    """
    if split not in ("train", "test"):
        raise StringStabError(f"split must be 'train' or 'test'; got {split!r}")
    windows = _moving([w for name in CYCLES for w in cut(cycle(name, dt=dt), seconds)])
    train, test = train_test_split(windows, test_fraction=TEST_FRACTION, seed=SPLIT_SEED)
    cyc = train if split == "train" else test
    synth = _moving([w for tr in _synthetic(split, dt) for w in cut(tr, seconds)])
    return [*cyc, *synth]


def _is_ngsim(path: Path) -> bool:
    with open_text(path, label=f"leader file {str(path)!r}",  # plain or gzip (.csv.gz)
                   expected="a 't, v' CSV or an NGSIM trajectory file") as fh:
        head = fh.readline()
    return "vehicle_id" in head.lower()


def leaders_from_files(paths: Sequence[str | Path], split: Split, *, seconds: float = 30.0,
                       dt: float = 0.1) -> list[Leader]:
    """Episodes from a user's files: ``t, v[, a]`` CSV files or NGSIM trajectory files.

    Parameters
    ----------
    paths : sequence of path
        The files.
    split : {"train", "test"}
        Training: CSV leaders cut into episodes of ``seconds``, the training part of the NGSIM
        pairs.  Test: CSV leaders whole, the test part of the NGSIM pairs.
    seconds, dt : float
        Episode length and step, s.

    Returns
    -------
    list of Leader
        The episodes: CSV leaders (cut into ``seconds``-long episodes for training) and
        NGSIM pairs.

    Raises
    ------
    StringStabError
        For a missing file, wrong columns, NaN, negative speeds (one line from the loaders), or
        a file that yields no episode.
    """
    out: list[Leader] = []
    for p in map(Path, paths):
        if not p.is_file():
            raise StringStabError(f"leader file {str(p)!r} does not exist; expected a 't, v' CSV "
                                  "or an NGSIM trajectory file")
        if _is_ngsim(p):
            pairs = load_ngsim_pairs(p)
            if len(pairs) < 2:
                raise StringStabError(f"NGSIM file {str(p)!r}: expected at least 2 car-following "
                                      f"pairs of >= 15 s; found {len(pairs)}")
            tr_pairs, te_pairs = train_test_split(pairs, test_fraction=TEST_FRACTION, seed=SPLIT_SEED)
            out += tr_pairs if split == "train" else te_pairs
        else:
            tr = load_csv(p, dt=dt)
            if split == "train":
                parts = cut(tr, seconds) if tr.duration > seconds else [tr]
                out += _moving(parts) or parts
            else:
                out.append(tr)
    if not out:
        raise StringStabError(f"no {split} episodes in {[str(p) for p in paths]}")
    return out
