"""Progress of a long SUMO run: a tqdm bar on a terminal, periodic one-line reports otherwise."""

from __future__ import annotations

import sys
import time
from typing import Any

__all__ = ["Progress"]


class Progress:
    """Count steps; show a bar (stderr is a terminal) or print a line every ``every`` seconds.

    Parameters
    ----------
    total : int
        Steps of the run.
    desc : str
        What runs (e.g. ``"sumo run"``).
    enabled : bool
        False: silent (tests, library calls).
    every : float
        Seconds between report lines when stderr is not a terminal.
    """

    def __init__(self, total: int, desc: str, *, enabled: bool = True, every: float = 10.0) -> None:
        self.total, self.desc, self.every = int(total), desc, float(every)
        self.enabled = enabled
        self.n = 0
        self._bar: Any = None
        self._t0 = self._last = time.monotonic()
        if enabled and sys.stderr.isatty():
            from tqdm.auto import tqdm

            self._bar = tqdm(total=self.total, desc=desc, unit="step", mininterval=0.5)

    def update(self, n: int = 1) -> None:
        """Count ``n`` more steps."""
        self.n += n
        if not self.enabled:
            return
        if self._bar is not None:
            self._bar.update(n)
            return
        now = time.monotonic()
        if now - self._last >= self.every:
            self._last = now
            print(f"{self.desc}: {self.n}/{self.total} steps ({100.0 * self.n / max(self.total, 1):.0f} %, "
                  f"{now - self._t0:.0f} s)", file=sys.stderr, flush=True)

    def close(self) -> None:
        """Close the bar."""
        if self._bar is not None:
            self._bar.close()
            self._bar = None
