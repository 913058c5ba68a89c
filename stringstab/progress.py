"""Progress of long work: a bar on a terminal, plain lines otherwise, honest times left.

Every command that can run for more than a few seconds reports through :class:`Progress`
(the one policy of the package):

* **on a terminal** (the stream is a TTY) a tqdm bar, without tqdm's monitor thread (no thread
  may run when the package forks, :mod:`stringstab.parallel`);
* **anywhere else** (a log, a CI job, a pipe, a redirected stderr) plain lines, never a
  carriage return: one every ``every`` seconds with the share done, the time elapsed and the
  time left, and a last line when the work is done;
* **the time left** comes from :class:`Pace`: nothing during a warm-up (the first unit, which
  pays for imports and caches, then :attr:`Pace.WARMUP` seconds), then the pace of the last
  :attr:`Pace.WINDOW` seconds (a moving average), not the pace since the start.

Lines go to stderr, so results on stdout stay clean.  Work done in stages (simulations, then
figures) reports each stage with its own :class:`Progress`, so that no stage is silent.
"""

from __future__ import annotations

import collections
import sys
import time
from collections.abc import Callable, Iterable, Iterator
from types import TracebackType
from typing import Any, TextIO, TypeVar

__all__ = ["Pace", "Progress", "duration", "is_terminal"]

T = TypeVar("T")


def duration(seconds: float) -> str:
    """``seconds`` for people: ``42 s``, ``3 min 05 s``, ``1 h 02 min``.

    Parameters
    ----------
    seconds : float
        A duration, s (negative values count as 0; rounded to whole seconds).

    Returns
    -------
    str
        The duration in s, min and s, or h and min.

    Examples
    --------
    >>> duration(42.4), duration(185), duration(3725)
    ('42 s', '3 min 05 s', '1 h 02 min')
    """
    s = round(max(seconds, 0.0))
    if s < 60:
        return f"{s} s"
    if s < 3600:
        return f"{s // 60} min {s % 60:02d} s"
    return f"{s // 3600} h {(s % 3600) // 60:02d} min"


def is_terminal(stream: Any) -> bool:
    """Whether ``stream`` is a terminal (a bar may redraw itself there with carriage returns).

    Parameters
    ----------
    stream : file-like
        The stream progress goes to.

    Returns
    -------
    bool
        ``stream.isatty()``, False when it has none or it fails (a closed stream).
    """
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError, OSError):
        return False


class Pace:
    """The pace of work from a moving window of samples, after a warm-up: the time left.

    Samples ``(t, done)`` are added as work is done (:meth:`add`).  The first sample is the
    *anchor*: whatever happened before it (start-up, imports, the first unit) is not counted.
    The time left is given once ``now − t_anchor ≥ warmup`` and some work was done after the
    anchor; it is then ``remaining / rate`` with

        rate = (done − done_ref) / (now − t_ref),

    where ``done`` is the work done by ``now`` and ``(t_ref, done_ref)`` the newest sample at
    least ``window`` seconds old (the anchor while none is): the pace of about the last
    ``window`` seconds, which slows as time passes without progress.

    Parameters
    ----------
    warmup : float, optional
        Seconds after the anchor without an estimate (default :attr:`WARMUP`).
    window : float, optional
        Seconds of the moving window (default :attr:`WINDOW`).

    Examples
    --------
    Ten units a second, from t = 2 s (after 2 s of start-up):

    >>> p = Pace(warmup=5.0, window=30.0)
    >>> for t in range(2, 10):
    ...     p.add(float(t), 10 * (t - 2))
    >>> p.left(6.0, 40, 100) is None  # 4 s after the anchor: still warming up
    True
    >>> p.left(9.0, 70, 100)  # (70 - 0) units / (9 - 2) s = 10 units/s; 30 units left
    3.0
    """

    #: Default seconds after the first unit before a time left is given.
    WARMUP: float = 10.0
    #: Default seconds of the moving window.
    WINDOW: float = 120.0

    def __init__(self, warmup: float | None = None, window: float | None = None) -> None:
        self.warmup = Pace.WARMUP if warmup is None else float(warmup)
        self.window = Pace.WINDOW if window is None else float(window)
        self._samples: collections.deque[tuple[float, float]] = collections.deque()
        self._anchor: tuple[float, float] | None = None

    def add(self, t: float, done: float) -> None:
        """Record that ``done`` units were done at time ``t`` (times non-decreasing).

        Parameters
        ----------
        t : float
            The time, s (any clock, the same for every call).
        done : float
            Units done in all by then.
        """
        if self._anchor is None:
            self._anchor = (t, done)
        self._samples.append((t, done))
        # keep one sample at least a window old (the reference), drop the older ones
        while len(self._samples) > 2 and self._samples[1][0] <= t - self.window:
            self._samples.popleft()

    def rate(self, now: float, done: float) -> float | None:
        """Units per second over the moving window; None during the warm-up.

        Parameters
        ----------
        now : float
            The current time, s.
        done : float
            Units done in all by ``now``.

        Returns
        -------
        float or None
            The pace, or None before the warm-up is over or without work after the anchor.
        """
        if self._anchor is None or now - self._anchor[0] < self.warmup:
            return None
        ref = self._anchor
        for s in self._samples:
            if s[0] <= now - self.window:
                ref = s
            else:
                break
        if done <= ref[1] or now <= ref[0]:
            return None
        return (done - ref[1]) / (now - ref[0])

    def left(self, now: float, done: float, total: float) -> float | None:
        """Seconds left until ``total`` units are done, at the current :meth:`rate`.

        Parameters
        ----------
        now : float
            The current time, s.
        done : float
            Units done in all by ``now``.
        total : float
            Units in all.

        Returns
        -------
        float or None
            The estimate, or None while there is none (warm-up).
        """
        r = self.rate(now, done)
        return None if r is None else max(total - done, 0.0) / r


def _bar_class() -> type:
    """A tqdm bar that starts no monitor thread and shows :class:`Pace`'s time left."""
    from tqdm.std import tqdm

    class Bar(tqdm):  # type: ignore[misc]
        monitor_interval = 0  # no TMonitor thread: the package may fork while a bar is open

        def __init__(self, *args: Any, left: Callable[[], str], **kwargs: Any) -> None:
            self._left = left
            super().__init__(*args, **kwargs)

        @property
        def format_dict(self) -> dict[str, Any]:
            d = dict(super().format_dict)
            d["left"] = self._left()
            return d

    return Bar


class Progress:
    """Report ``total`` units of work as they are done (see the module docstring).

    Parameters
    ----------
    total : int
        Units of work (episodes, steps, leaders, figures).
    desc : str
        What is being done, e.g. ``"stringstab evaluate: episodes"``.
    unit : str
        Name of a unit, for the lines.
    enabled : bool
        False: silent (``--no-progress``).
    stream : file, optional
        Where to report (default: stderr).
    every : float, optional
        Seconds between two lines when not on a terminal (default :attr:`EVERY`).
    tty : bool, optional
        Force the bar (True) or the lines (False); default: :func:`is_terminal` of the stream.
    initial : int
        Units already done (a resumed run); the time left is estimated from this call's pace.
    clock : callable, optional
        The clock, s (default :func:`time.perf_counter`; tests pass a synthetic one).
    warmup, window : float, optional
        Of the :class:`Pace` (defaults :attr:`Pace.WARMUP`, :attr:`Pace.WINDOW`).

    Examples
    --------
    >>> import io
    >>> buf = io.StringIO()
    >>> with Progress(4, "demo", unit="step", stream=buf, every=0.0, tty=False) as p:
    ...     p.update(2)
    ...     p.update(2)
    >>> print(buf.getvalue().splitlines()[0])
    demo: 2/4 step (50%), 0 s elapsed
    """

    #: Default seconds between two progress lines.
    EVERY: float = 10.0
    #: Seconds between two samples of the pace (bounds the work of a very frequent update).
    SAMPLE: float = 0.5

    def __init__(self, total: int, desc: str, *, unit: str = "it", enabled: bool = True,
                 stream: TextIO | None = None, every: float | None = None, tty: bool | None = None,
                 initial: int = 0, clock: Callable[[], float] | None = None,
                 warmup: float | None = None, window: float | None = None) -> None:
        self.total = max(int(total), 0)
        self.initial = int(initial)
        self.desc = desc
        self.unit = unit
        self.enabled = enabled
        self.stream = stream if stream is not None else sys.stderr
        self.every = Progress.EVERY if every is None else every
        self.done = self.initial
        self.clock = clock if clock is not None else time.perf_counter
        self.pace = Pace(warmup, window)
        self._t0 = self.clock()
        self._last = self._t0
        self._sampled = -float("inf")
        self._lines = 0
        self._bar: Any = None
        if enabled and (tty if tty is not None else is_terminal(self.stream)):
            self._bar = _bar_class()(
                total=self.total, initial=self.initial, desc=desc, unit=unit, file=self.stream,
                mininterval=0.5, leave=False, left=self._left_text, unit_scale=self.total >= 10_000,
                bar_format="{l_bar}{bar}| {n_fmt}/{total_fmt} [{elapsed}{left}{postfix}]")

    @property
    def bar(self) -> Any:
        """The tqdm bar (on a terminal), else None: for ``set_postfix``."""
        return self._bar

    def update(self, n: int = 1) -> None:
        """``n`` more units are done.

        Parameters
        ----------
        n : int
            Units just completed.
        """
        self.done += n
        if not self.enabled:
            return
        now = self.clock()
        if now - self._sampled >= self.SAMPLE or self.done >= self.total:
            self._sampled = now
            self.pace.add(now, self.done)
        if self._bar is not None:
            self._bar.update(n)
            return
        if now - self._last >= self.every and self.done < self.total:
            self._last = now
            self._line(now)

    def over(self, items: Iterable[T], per_item: int = 1) -> Iterator[T]:
        """Yield ``items``, counting ``per_item`` units after each.

        Parameters
        ----------
        items : iterable
            The work items.
        per_item : int
            Units each stands for.

        Yields
        ------
        object
            Each item, in turn.
        """
        for item in items:
            yield item
            self.update(per_item)

    def left(self, now: float | None = None) -> float | None:
        """Seconds left (:class:`Pace`), or None during the warm-up or once all is done.

        Parameters
        ----------
        now : float, optional
            The clock's current reading (default: read it now).

        Returns
        -------
        float or None
            The estimate.
        """
        if self.done >= self.total:
            return None
        return self.pace.left(self.clock() if now is None else now, self.done, self.total)

    def _left_text(self) -> str:
        left = self.left()
        return "" if left is None else f", ~{duration(left)} left"

    def timing(self, now: float | None = None) -> str:
        """``"<elapsed> elapsed"`` and, after the warm-up, ``", ~<left> left"``.

        Parameters
        ----------
        now : float, optional
            The clock's current reading (default: read it now).

        Returns
        -------
        str
            Elapsed time and, while work remains and the pace is known, the time left.
        """
        now = self.clock() if now is None else now
        left = self.left(now)
        eta = "" if left is None else f", ~{duration(left)} left"
        return f"{duration(now - self._t0)} elapsed{eta}"

    def _line(self, now: float) -> None:
        share = self.done / self.total if self.total else 1.0
        self._lines += 1
        print(f"{self.desc}: {self.done}/{self.total} {self.unit} ({100 * share:.0f}%), "
              f"{self.timing(now)}", file=self.stream, flush=True)

    def close(self) -> None:
        """Close the bar, or print the last line (the time it took).

        The last line is printed when lines were printed or the work took longer than ``every``.
        """
        if self._bar is not None:
            self._bar.close()
            self._bar = None
        elif self.enabled and (self._lines or self.clock() - self._t0 >= self.every):
            print(f"{self.desc}: {self.done}/{self.total} {self.unit} done in "
                  f"{duration(self.clock() - self._t0)}", file=self.stream, flush=True)
            self.enabled = False  # closed: a second close prints nothing

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()
