"""Random loss of V2V messages: independent (Bernoulli) or in bursts (Gilbert–Elliott), seeded.

Every link (follower) has its own loss process, advanced only when a message is due on it:

Bernoulli (``burst=None``)
    each message is lost with probability p, independently.
Gilbert–Elliott (``burst=B``)
    the link is a two-state Markov chain, Good (delivers) and Bad (loses), stepped once per
    due message.  With P(Good → Bad) = p/(B(1 − p)) and P(Bad → Good) = 1/B the stationary
    loss rate is p and a run of lost messages lasts B messages on average (geometric)
    (Gilbert 1960; Elliott 1963; the two-parameter "simplified Gilbert" model of the V2V
    literature).  It needs p/(B(1 − p)) ≤ 1, i.e. p ≤ B/(B + 1); B = 1/(1 − p) is Bernoulli.
    Each chain starts in its stationary distribution (Bad with probability p).

p = 0 loses nothing (no random number is drawn); p = 1 loses every message.

References
----------
E. N. Gilbert, "Capacity of a burst-noise channel", Bell System Technical Journal 39 (1960).
E. O. Elliott, "Estimates of error rates for codes on burst-noise channels", Bell System
Technical Journal 42 (1963).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError, show

__all__ = ["MessageLoss", "check_loss"]

Bool = npt.NDArray[np.bool_]


def check_loss(loss: Any, burst: Any = None) -> tuple[float, float | None]:
    """The loss rate p ∈ [0, 1] and the mean burst length B ≥ 1 (or None), checked.

    Parameters
    ----------
    loss : float
        Mean message loss rate p.
    burst : float, optional
        Mean number of messages lost in a row (Gilbert–Elliott); None for independent losses.

    Returns
    -------
    (float, float or None)
        p and B.

    Raises
    ------
    StringStabError
        p not a number in [0, 1]; B not a finite number ≥ 1; p > B/(B + 1) (no chain has
        that rate with bursts that short).

    Examples
    --------
    >>> check_loss(0.02, 3)
    (0.02, 3.0)
    >>> check_loss(1.5)
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: loss (message loss rate) must be a number in [0, 1]; got 1.5
    """
    try:
        p = float(loss)
    except (TypeError, ValueError) as e:
        raise StringStabError(f"loss (message loss rate) must be a number in [0, 1]; got {show(loss)}") from e
    if not (0.0 <= p <= 1.0):
        raise StringStabError(f"loss (message loss rate) must be a number in [0, 1]; got {show(loss)}")
    if burst is None:
        return p, None
    try:
        b = float(burst)
    except (TypeError, ValueError) as e:
        raise StringStabError(f"burst (mean messages lost in a row) must be a number >= 1; "
                              f"got {show(burst)}") from e
    if not (math.isfinite(b) and b >= 1.0):
        raise StringStabError(f"burst (mean messages lost in a row) must be a finite number >= 1; "
                              f"got {show(burst)}")
    if p < 1.0 and p > b / (b + 1.0) * (1 + 1e-12):
        raise StringStabError(f"loss {p:g} with bursts of {b:g} messages on average is impossible: a "
                              f"loss rate of {p:g} needs bursts of at least p/(1 − p) = "
                              f"{p / (1 - p):.4g} messages; expected loss <= burst/(burst + 1) = "
                              f"{b / (b + 1):.4g}")
    return p, b


class MessageLoss:
    """The loss process of every link of a batch: :meth:`lost` for the messages now due.

    Parameters
    ----------
    loss : float
        Mean loss rate p ∈ [0, 1].
    burst : float or None
        Mean burst length B ≥ 1 (Gilbert–Elliott), or None (Bernoulli).
    shape : tuple of int
        The links, ``(n_platoons, n_followers)``.
    rng : numpy.random.Generator
        The seeded source of randomness (owned by this process).
    """

    def __init__(self, loss: float, burst: float | None, shape: tuple[int, ...],
                 rng: np.random.Generator) -> None:
        self.p, self.burst = check_loss(loss, burst)
        self.shape, self.rng = shape, rng
        self.bad: Bool | None = None
        if self.burst is not None and 0.0 < self.p < 1.0:
            self.p_gb = self.p / (self.burst * (1.0 - self.p))
            self.p_bg = 1.0 / self.burst
            self.bad = rng.random(shape) < self.p  # the stationary start

    def lost(self, due: Bool) -> Bool:
        """Which of the messages due now are lost (False where none is due).

        Parameters
        ----------
        due : bool array of ``shape``
            Links on which a message is due at this step; the Gilbert–Elliott chains of these
            links (only) take one step.

        Returns
        -------
        bool array of ``shape``
            True where a due message is lost.
        """
        if self.p == 0.0 or not due.any():
            return np.zeros(self.shape, dtype=bool)
        if self.p == 1.0:
            return np.array(due, dtype=bool, copy=True)
        r = self.rng.random(self.shape)
        if self.bad is None:
            return due & (r < self.p)
        # one chain step on the due links: Bad stays Bad with 1 − p_bg, Good turns Bad with p_gb
        nxt = np.where(self.bad, r >= self.p_bg, r < self.p_gb)
        self.bad = np.where(due, nxt, self.bad)
        return due & self.bad

    def reset(self, rows: Any = None) -> None:
        """Restart the chains of ``rows`` (default all) in their stationary distribution.

        Parameters
        ----------
        rows : index array, optional
            Platoons (first axis) to restart.
        """
        if self.bad is not None:
            r: Any = slice(None) if rows is None else np.asarray(rows)
            self.bad[r] = self.rng.random(self.bad[r].shape) < self.p
