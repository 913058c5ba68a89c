"""Memory a command will need, estimated before it allocates, and refused when it cannot fit.

A grid of ``--n`` points per axis, a platoon of ``--followers`` vehicles or a batch file of
triples each has a known memory cost per element; :func:`refuse_if_too_big` compares the
estimate with the memory the machine has available now and refuses with both numbers (one
line, exit 2) instead of letting NumPy raise MemoryError after minutes, or the kernel kill
the process without a word.
"""

from __future__ import annotations

import os

from ..errors import StringStabError

__all__ = ["available_bytes", "human_bytes", "refuse_if_too_big"]


def available_bytes() -> int:
    """The memory this process may still allocate: ``MemAvailable`` of ``/proc/meminfo``.

    Falls back to the physical memory (``os.sysconf``), then to 8 GiB where neither is known.

    Returns
    -------
    int
        Bytes.
    """
    try:
        with open("/proc/meminfo", encoding="ascii") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return int(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (AttributeError, ValueError, OSError):
        return 8 << 30


def human_bytes(n: float) -> str:
    """``n`` bytes in binary units, e.g. ``74.5 GiB``.

    Parameters
    ----------
    n : float
        A number of bytes.

    Returns
    -------
    str
        Whole bytes below 1 KiB, else one decimal in KiB ... PiB.

    Examples
    --------
    >>> human_bytes(80e9), human_bytes(512)
    ('74.5 GiB', '512 B')
    """
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB"):
        if abs(n) < 1024 or unit == "PiB":
            return f"{n:.0f} {unit}" if unit == "B" else f"{n:.1f} {unit}"
        n /= 1024
    raise AssertionError("unreachable")  # pragma: no cover


def refuse_if_too_big(what: str, nbytes: float, hint: str, *, limit: float | None = None) -> None:
    """Refuse (StringStabError) when ``nbytes`` exceeds the memory available (or ``limit``).

    Parameters
    ----------
    what : str
        The request, as the user wrote it (``"--n 100000"``).
    nbytes : float
        The estimated peak memory of the request, in bytes.
    hint : str
        How to make it fit (``"expected --n <= 3000"``).
    limit : float, optional
        Bytes allowed; default :func:`available_bytes`.

    Raises
    ------
    StringStabError
        With the estimate, the limit and the hint.

    Examples
    --------
    >>> refuse_if_too_big("--n 10", 800, "fewer points", limit=1e9)
    >>> refuse_if_too_big("--n 100000", 80e9, "expected --n <= 3000", limit=8 << 30)
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: --n 100000 needs about 74.5 GiB of memory; 8.0 GiB is available; expected --n <= 3000
    """
    cap = float(available_bytes() if limit is None else limit)
    if nbytes > cap:
        raise StringStabError(
            f"{what} needs about {human_bytes(nbytes)} of memory; {human_bytes(cap)} is available; {hint}")


#: Peak memory per vehicle and time step of a platoon run (measured with ``simulate --leader
#: us06 --no-figures``: peak RSS 50 MB with 10 followers, 219 MB with 400, 6000 steps: ~74 B
#: per vehicle-step), doubled for the figures and the trajectory file, and the fixed part.
BYTES_PER_VEHICLE_STEP = 160
BYTES_PLATOON_BASE = 150e6


def refuse_platoon(followers: int, steps: int, what: str) -> None:
    """Refuse a platoon run whose estimated memory exceeds what is available.

    Parameters
    ----------
    followers : int
        Followers in the platoon.
    steps : int
        Time steps of the run (the leader's samples).
    what : str
        The request as written (``"--followers 1000000000"``).

    Raises
    ------
    StringStabError
        With the estimate, the memory available and the largest platoon that fits.
    """
    cap = available_bytes()
    per = BYTES_PER_VEHICLE_STEP * max(int(steps), 1)
    fit = max(0, int((cap - BYTES_PLATOON_BASE) / per) - 1)
    refuse_if_too_big(f"{what} ({steps} steps)", BYTES_PLATOON_BASE + per * (float(followers) + 1),
                      f"expected at most about {fit} followers on this machine", limit=cap)
