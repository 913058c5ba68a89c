"""Reading recorded platoons for identification: :func:`read_logs`.

The formats are read by :func:`stringstab.io.platoon_logs.read_platoon_logs` (the bottom I/O
layer); NGSIM trajectory files are cut into leader–follower pairs by the parser the simulator
already uses for its leaders (:func:`stringstab.traffic.load_ngsim_pairs`), which this module
hands to the reader, so the I/O layer does not import the simulator.

Two real logs ship with the package (``stringstab/data/openacc/``, the JRC's OpenACC database,
CC BY 4.0: see the README there): :func:`example_log` gives their paths.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import StringStabError, show
from ..io.platoon_logs import PlatoonLog, read_platoon_logs

__all__ = ["EXAMPLES", "example_log", "read_logs", "read_ngsim"]

#: The OpenACC logs shipped in ``stringstab/data/openacc/``: name -> (file, what it is).
EXAMPLES: dict[str, tuple[str, str]] = {
    "acc": ("zalazone_acc_short_dynamic_part1.csv.gz",
            "OpenACC, ZalaZONE: 6 cars, every follower on its factory ACC (short setting)"),
    "human": ("zalazone_human_handling_part22.csv.gz",
              "OpenACC, ZalaZONE: 11 cars driven by people (handling track)"),
}


def example_log(name: str) -> Path:
    """The path of a shipped example log (:data:`EXAMPLES`).

    Parameters
    ----------
    name : {"acc", "human"}
        Which log.

    Returns
    -------
    Path
        The file inside the installed package (a gzip-compressed OpenACC CSV).

    Raises
    ------
    StringStabError
        For another name, or when the package was installed without its data.

    Examples
    --------
    >>> example_log("acc").name
    'zalazone_acc_short_dynamic_part1.csv.gz'
    """
    if name not in EXAMPLES:
        raise StringStabError(f"--example must be one of {', '.join(EXAMPLES)}; got {show(name)}")
    path = Path(__file__).resolve().parents[1] / "data" / "openacc" / EXAMPLES[name][0]
    if not path.is_file():
        raise StringStabError(f"the example log {EXAMPLES[name][0]} is not in this installation "
                              f"(expected {path}); reinstall stringstab with its package data")
    return path


def read_ngsim(path: Path, min_duration: float) -> list[PlatoonLog]:
    """One two-vehicle :class:`PlatoonLog` per leader–follower pair of an NGSIM file.

    Parameters
    ----------
    path : Path
        The US-101 / I-80 trajectory file.
    min_duration : float
        Shortest pair kept, s.

    Returns
    -------
    list of PlatoonLog
        In the order of :func:`stringstab.traffic.load_ngsim_pairs` (SI units; the recorded
        accelerations kept; gap bumper to bumper with the leader's length).

    Raises
    ------
    StringStabError
        When the file has no pair of that length.
    """
    from ..traffic.loaders import load_ngsim_pairs

    logs = []
    for pr in load_ngsim_pairs(path, min_duration=min_duration):
        n = pr.leader.n_steps
        t = np.arange(n, dtype=np.float64) * pr.leader.dt
        speed = np.stack([pr.leader.speed, pr.follower.speed])
        acc = np.stack([pr.leader.accel, pr.follower.accel])
        names = (f"ngsim-{pr.leader_id}", f"ngsim-{pr.follower_id}")
        logs.append(PlatoonLog(t, (0, 1), names, speed, {1: pr.gap}, acc, str(path), "ngsim",
                               {"start_frame": pr.start_frame, "location": pr.location}))
    if not logs:
        raise StringStabError(
            f"platoon log {show(str(path))}: no leader-follower pair of at least {min_duration:g} s "
            "in this NGSIM file")
    return logs


def read_logs(path: str | Path, *, min_duration: float = 30.0) -> list[PlatoonLog]:
    """Read an OpenACC, plain CSV or NGSIM log.

    Through :func:`stringstab.io.read_platoon_logs` with the NGSIM reader :func:`read_ngsim`.

    Parameters
    ----------
    path : path
        The file.
    min_duration : float
        For NGSIM files, the shortest pair kept, s.

    Returns
    -------
    list of PlatoonLog
    """
    return read_platoon_logs(path, min_duration=min_duration, ngsim=read_ngsim)
