"""Memory a request will need, estimated before it allocates, and refused when it cannot fit.

The one estimator of the toolkit: a map or a certified grid of gain points (:func:`grid_bytes`,
``region`` and the sweep's ``region``/``certify`` points), a platoon of followers over a
leader's steps (:func:`platoon_bytes`, ``simulate``, ``evaluate``, ``hcfs``), a training run
(:func:`training_bytes`, ``train`` and the sweep's ``train`` points) or a batch file of triples
each has a known memory cost per element, measured; :func:`refuse_if_too_big` compares the
estimate with the memory available (the machine's now, or a Dask worker's limit) and refuses
with both numbers (one line, exit 2) instead of letting NumPy raise MemoryError after minutes,
or the kernel (or a Dask nanny) kill the process without a word.
"""

from __future__ import annotations

import os

from .errors import StringStabError

__all__ = [
    "BYTES_GRID_BASE",
    "BYTES_PER_ENV",
    "BYTES_PER_POINT",
    "BYTES_PER_TRANSITION",
    "BYTES_PER_VEHICLE_STEP",
    "BYTES_PLATOON_BASE",
    "BYTES_TRAINING_BASE",
    "available_bytes",
    "grid_bytes",
    "grid_fit",
    "human_bytes",
    "platoon_bytes",
    "refuse_if_too_big",
    "refuse_platoon",
    "training_bytes",
]


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


def platoon_bytes(followers: float, steps: int) -> float:
    """Peak memory of a platoon run: the fixed part and every vehicle's every step.

    Parameters
    ----------
    followers : float
        Followers in the platoon (or summed over the platoons run together).
    steps : int
        Time steps of the run (the leader's samples).

    Returns
    -------
    float
        Bytes: :data:`BYTES_PLATOON_BASE` + :data:`BYTES_PER_VEHICLE_STEP` (followers + 1) steps.

    Examples
    --------
    >>> human_bytes(platoon_bytes(10, 6000))
    '153.1 MiB'
    """
    return BYTES_PLATOON_BASE + BYTES_PER_VEHICLE_STEP * max(int(steps), 1) * (float(followers) + 1)


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
    refuse_if_too_big(f"{what} ({steps} steps)", platoon_bytes(followers, steps),
                      f"expected at most about {fit} followers on this machine", limit=cap)


#: Peak memory per grid point of a map (measured: peak RSS 171 MB at 201², 465 MB at 801², all
#: three methods and the figures: ~490 B per point) and the fixed part, rounded up.
BYTES_PER_POINT = 600
BYTES_GRID_BASE = 250e6


def grid_bytes(points: float) -> float:
    """Peak memory of a map or a certified grid of ``points`` gain triples.

    Parameters
    ----------
    points : float
        Grid points (the product of the points per axis).

    Returns
    -------
    float
        Bytes: :data:`BYTES_GRID_BASE` + :data:`BYTES_PER_POINT` per point.

    Examples
    --------
    >>> human_bytes(grid_bytes(801 ** 2))
    '605.5 MiB'
    """
    return BYTES_GRID_BASE + BYTES_PER_POINT * float(points)


def grid_fit(cap: float, dims: int) -> int:
    """The largest number of points per axis of a ``dims``-D grid that fits in ``cap`` bytes.

    Parameters
    ----------
    cap : float
        Bytes available.
    dims : int
        Axes of the grid (2 or 3).

    Returns
    -------
    int
        Points per axis, at least 2.

    Examples
    --------
    >>> grid_fit(8 << 30, 3)
    240
    """
    return max(2, int((max(cap - BYTES_GRID_BASE, 0.0) / BYTES_PER_POINT) ** (1 / dims)))


#: Memory per parallel training environment (train --algo idl, peak RSS 1022 MB with 4 and
#: 1023 MB with 2048 environments: ~0.6 kB each), rounded up; the fixed part (the trainer,
#: torch) is that 1022 MB, rounded up.
BYTES_PER_ENV = 2048
BYTES_TRAINING_BASE = 1.1e9
#: Replay-buffer memory per transition: obs, next obs (up to 16 float32 each), action (up to 3),
#: reward, done (``stringstab.rl.buffer``: float32 arrays), 4 (2·16 + 3 + 2) = 148 B, rounded up
#: and doubled for the copy a checkpoint writes.
BYTES_PER_TRANSITION = 320


def training_bytes(num_envs: int, buffer_size: int) -> float:
    """Peak memory of a training run: the trainer, its environments and its replay buffer.

    Parameters
    ----------
    num_envs : int
        Parallel environments.
    buffer_size : int
        Replay-buffer capacity, transitions.

    Returns
    -------
    float
        Bytes: :data:`BYTES_TRAINING_BASE` + :data:`BYTES_PER_ENV` per environment +
        :data:`BYTES_PER_TRANSITION` per transition.

    Examples
    --------
    >>> human_bytes(training_bytes(8, 1_000_000))
    '1.3 GiB'
    """
    return (BYTES_TRAINING_BASE + BYTES_PER_ENV * float(num_envs)
            + BYTES_PER_TRANSITION * float(buffer_size))
