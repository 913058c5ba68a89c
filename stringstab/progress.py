"""Progress of long work: a tqdm bar on a terminal, periodic one-line progress otherwise.

Every command that can run for more than a few seconds reports through :class:`Progress`:
on a terminal (stderr is a TTY) a tqdm bar; in a log, a CI job or a pipe, one line every
``every`` seconds with the share done, the time elapsed and an estimate of the time left,
and a last line when the work is done.  Lines go to stderr, so results on stdout stay clean.
"""

from __future__ import annotations

import sys
import time
from types import TracebackType
from typing import Any, TextIO

__all__ = ["Progress", "duration"]


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


class Progress:
    """Report ``total`` units of work as they are done.

    Parameters
    ----------
    total : int
        Units of work (episodes, steps, leaders).
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
        Force the bar (True) or the lines (False); default: ``stream.isatty()``.
    initial : int
        Units already done (a resumed run); the time left is estimated from this call's pace.

    Examples
    --------
    >>> import io
    >>> buf = io.StringIO()
    >>> with Progress(4, "demo", unit="step", stream=buf, every=0.0, tty=False) as p:
    ...     p.update(2)
    ...     p.update(2)
    >>> print(buf.getvalue().splitlines()[0].split(",")[0])
    demo: 2/4 step (50%)
    """

    #: Default seconds between two progress lines.
    EVERY: float = 10.0

    def __init__(self, total: int, desc: str, *, unit: str = "it", enabled: bool = True,
                 stream: TextIO | None = None, every: float | None = None, tty: bool | None = None,
                 initial: int = 0) -> None:
        self.total = max(int(total), 0)
        self.initial = int(initial)
        self.desc = desc
        self.unit = unit
        self.enabled = enabled
        self.stream = stream if stream is not None else sys.stderr
        self.every = Progress.EVERY if every is None else every
        self.done = self.initial
        self._t0 = time.perf_counter()
        self._last = self._t0
        self._bar: Any = None
        is_tty = tty if tty is not None else bool(getattr(self.stream, "isatty", lambda: False)())
        if enabled and is_tty:
            from tqdm.auto import tqdm

            self._bar = tqdm(total=self.total, initial=self.initial, desc=desc, unit=unit,
                             file=self.stream, mininterval=0.5, leave=False)

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
        if self._bar is not None:
            self._bar.update(n)
            return
        now = time.perf_counter()
        if now - self._last >= self.every and self.done < self.total:
            self._last = now
            self._line(now)

    def timing(self, now: float | None = None) -> str:
        """``"<elapsed> elapsed, ~<left> left"``, the time left from the pace so far.

        The time left is omitted before the first unit and once all are done.

        Parameters
        ----------
        now : float, optional
            The current ``time.perf_counter()`` reading (default: read it now).

        Returns
        -------
        str
            Elapsed time and, while work remains, the estimated time left.
        """
        el = (time.perf_counter() if now is None else now) - self._t0
        rate = (self.done - self.initial) / el if el > 0 else 0.0  # this call's pace
        eta = (f", ~{duration((self.total - self.done) / rate)} left"
               if rate > 0 and self.done < self.total else "")
        return f"{duration(el)} elapsed{eta}"

    def _line(self, now: float) -> None:
        share = self.done / self.total if self.total else 1.0
        print(f"{self.desc}: {self.done}/{self.total} {self.unit} ({100 * share:.0f}%), "
              f"{self.timing(now)}", file=self.stream, flush=True)

    def close(self) -> None:
        """Close the bar, or print the last line (the time it took).

        The last line is printed when lines were printed or the work took longer than ``every``.
        """
        if self._bar is not None:
            self._bar.close()
            self._bar = None
        elif self.enabled and (self._last > self._t0
                               or time.perf_counter() - self._t0 >= self.every):
            print(f"{self.desc}: {self.done}/{self.total} {self.unit} done in "
                  f"{duration(time.perf_counter() - self._t0)}", file=self.stream, flush=True)
            self._last = self._t0

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()
