"""The bundled standard driving cycles (EPA UDDS, HWFET, US06; UN/ECE WLTC class 3b) as leaders.

The 1 Hz speed tables live in ``stringstab/data/cycles`` (sources and licences in its
README.md).
"""

from __future__ import annotations

import csv
from importlib import resources

import numpy as np

from ..constants import DT, SPEED_MAX
from ..errors import StringStabError, show
from .trajectory import Trajectory, from_speed

__all__ = ["CYCLES", "CYCLE_ALIASES", "cycle"]

#: Bundled driving cycles: name -> (file, description).
CYCLES: dict[str, tuple[str, str]] = {
    "udds": ("udds.csv", "EPA Urban Dynamometer Driving Schedule (FTP-72), 1369 s, stop-and-go"),
    "hwfet": ("hwfet.csv", "EPA Highway Fuel Economy Test, 765 s, highway"),
    "us06": ("us06.csv", "EPA US06 Supplemental FTP, 600 s, aggressive"),
    "wltc3b": ("wltc_3b.csv", "UN/ECE WLTC class 3b, 1800 s, four phases"),
}
#: Other accepted names of the cycles.
CYCLE_ALIASES: dict[str, str] = {"wltc": "wltc3b", "wltc_3b": "wltc3b", "wltc-3b": "wltc3b",
                                 "ftp72": "udds"}


def cycle(name: str, *, dt: float = DT, speed_max: float | None = SPEED_MAX) -> Trajectory:
    """A bundled standard driving cycle, resampled to the step ``dt``.

    The 1 Hz speed samples are linearly interpolated; the acceleration is the slope over each
    step.  US06 and WLTC 3b exceed the IDL paper's road limit v_max = 33.3 m/s (Table 2) for
    24 s and 87 s; by default the leader's speed is capped there (``speed_max=None`` keeps it).

    Parameters
    ----------
    name : {"udds", "hwfet", "us06", "wltc3b"}
        Cycle name (case-insensitive; "wltc", "wltc_3b", "wltc-3b" are aliases of "wltc3b").
    dt : float
        Step, s.
    speed_max : float or None
        Speed cap, m/s.

    Returns
    -------
    Trajectory

    Raises
    ------
    StringStabError
        For an unknown cycle name.

    Examples
    --------
    >>> us06 = cycle("us06", dt=0.1)
    >>> us06.duration, round(float(us06.speed.max()), 1)
    (600.0, 33.3)
    """
    key = str(name).strip().lower()
    key = CYCLE_ALIASES.get(key, key)
    if key not in CYCLES:
        raise StringStabError(f"unknown driving cycle {show(name)}; expected one of {sorted(CYCLES)}")
    fname = CYCLES[key][0]
    res = resources.files("stringstab").joinpath("data").joinpath("cycles").joinpath(fname)
    with res.open("r", encoding="utf-8-sig") as fh:
        rows = list(csv.DictReader(fh))
    t = np.array([float(r["cycSecs"]) for r in rows])
    v = np.array([float(r["cycMps"]) for r in rows])
    tr = from_speed(t, np.maximum(v, 0.0), dt=dt, speed_max=speed_max, name=key)
    tr.meta.update(source=f"stringstab/data/cycles/{fname}", description=CYCLES[key][1])
    return tr
