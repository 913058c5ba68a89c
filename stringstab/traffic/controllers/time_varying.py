"""The eq-4 law with gains that change over time: :class:`TimeVaryingLinearController`.

The gains come from a schedule array, a CSV file or a :class:`~stringstab.io.GainTable` time
series (one series per follower or one for all), or a policy callable (the IDL agent outputs K
each step, eq 17).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from ...errors import StringStabError, show
from ...io.gain_table import GainTable
from ...params import DEFAULT_HEADWAY, positive
from .base import DEFAULT_STANDSTILL, Controller, Observation, time_headway_gap
from .linear import linear_law

__all__ = ["TimeVaryingLinearController"]

Array = npt.NDArray[np.float64]


class TimeVaryingLinearController(Controller):
    """The eq-4 law with gains that change over time.

    Parameters
    ----------
    schedule : array of shape (T, ..., 3) or callable
        Either gains per step (row ``k`` is used at step k; the last row is held after the
        end; extra middle axes broadcast against the batch), or a callable
        ``schedule(obs) -> array (..., 3)`` — e.g. an IDL policy mapping the eq-16 state to K.
    headway, standstill : float
        T* (s) and l_0 (m).

    Examples
    --------
    >>> c = TimeVaryingLinearController([[1.0, 0.5, 0.2], [2.0, 0.5, 0.2]])
    >>> c.time_varying
    True
    """

    time_varying = True

    def __init__(self, schedule: npt.ArrayLike | Callable[[Observation], npt.ArrayLike], *,
                 headway: float = DEFAULT_HEADWAY, standstill: float = DEFAULT_STANDSTILL) -> None:
        self._headway = positive("headway (T*)", headway, allow_zero=True)
        self.standstill = positive("standstill spacing l0", standstill, allow_zero=True)
        self._fn: Callable[[Observation], npt.ArrayLike] | None
        if callable(schedule):
            self._fn, self._table = schedule, None
        else:
            tab = np.asarray(schedule, dtype=np.float64)
            if tab.ndim < 2 or tab.shape[-1] != 3 or tab.shape[0] < 1:
                raise StringStabError(
                    f"a gain schedule must have shape (T, ..., 3) with columns k_x, k_v, k_a; got {tab.shape}"
                )
            if not np.isfinite(tab).all():
                raise StringStabError("a gain schedule must be finite; found NaN or inf")
            self._fn, self._table = None, tab
        self._last: tuple[int, Array] | None = None

    #: Followers with their own gain series (from a file with a ``vehicle`` column), else None.
    followers: int | None = None

    @classmethod
    def from_csv(cls, path: str | Path, *, headway: float = DEFAULT_HEADWAY,
                 standstill: float = DEFAULT_STANDSTILL) -> TimeVaryingLinearController:
        """Gains from a gain time series file, held from each ``t`` to the next.

        The file is read by :func:`stringstab.io.read_gains`, the reader of every command, so
        CSV (comment lines allowed), JSON, NPZ and Parquet files with columns ``t, k_x, k_v,
        k_a`` work, as does the bundled ``stringstab/data/examples/gain_rollout.csv``.  With a
        ``vehicle`` column, vehicle ``i`` (an integer, 1 = first follower) gets its own series
        and the platoon must have exactly those followers (see :meth:`from_table`).

        Parameters
        ----------
        path : str or Path
            The gain time series file.
        headway : float
            T* of the eq-3 spacing policy, s.
        standstill : float
            l_0, m.

        Returns
        -------
        TimeVaryingLinearController
            The controller; ``followers`` is the number of per-vehicle series, or None.

        Raises
        ------
        StringStabError
            If the file cannot be read, has no ``t`` column, or times are not increasing.
        """
        from ...io import read_gains

        return cls.from_table(read_gains(path), headway=headway, standstill=standstill)

    @classmethod
    def from_table(cls, table: GainTable, *, headway: float = DEFAULT_HEADWAY,
                   standstill: float = DEFAULT_STANDSTILL) -> TimeVaryingLinearController:
        """Gains from a :class:`~stringstab.io.GainTable` time series (see :meth:`from_csv`).

        Before the first ``t`` of a series its first gains apply, after the last its last.

        Parameters
        ----------
        table : GainTable
            Gains with times ``t`` (s) and optionally ``vehicle`` ids 1..N.
        headway : float
            T* of the eq-3 spacing policy, s.
        standstill : float
            l_0, m.

        Returns
        -------
        TimeVaryingLinearController
            The controller; at time t it runs the gains of the last row with ``t`` ≤ t (+1e-9 s).

        Raises
        ------
        StringStabError
            If there is no ``t`` column, vehicle ids are not 1..N, or a series' times are not
            strictly increasing; at run time, if the platoon does not have N followers.

        Examples
        --------
        >>> from stringstab.io import GainTable
        >>> import numpy as np
        >>> g = GainTable(np.array([1.2, 0.1]), np.array([0.5, 0.58]), np.array([0.6, 1.0]),
        ...               t=np.array([0.0, 5.0]), source="gains")
        >>> TimeVaryingLinearController.from_table(g).followers is None
        True
        """
        src = table.source
        if table.t is None:
            raise StringStabError(
                f"{src}: a gain time series needs a column t (s); found columns "
                f"{', '.join(table.columns)}"
            )
        t, K = table.t, table.K
        if table.vehicle is None:
            series = {0: (t, K)}
        else:
            ids = table.vehicle
            if ids.dtype.kind not in "iu" or ids.min() < 1:
                raise StringStabError(
                    f"{src}: vehicle ids must be the followers' positions 1, 2, ... (integers, "
                    f"1 = first behind the leader); found {show(sorted(set(ids.tolist()))[:5])}"
                )
            present = np.unique(ids)
            if present.tolist() != list(range(1, int(present.max()) + 1)):
                raise StringStabError(
                    f"{src}: expected a gain series for every follower 1..{int(present.max())}; "
                    f"found vehicles {show(present.tolist())}"
                )
            series = {int(v): (t[ids == v], K[ids == v]) for v in present}
        for v, (tv, _) in series.items():
            if (np.diff(tv) <= 0).any():
                i = int(np.argmax(np.diff(tv) <= 0))
                who = f" of vehicle {v}" if v else ""
                raise StringStabError(
                    f"{src}: t{who} must be strictly increasing; found t = {show(tv[i])} "
                    f"then {show(tv[i + 1])}"
                )
        times = np.unique(t)
        # gains in force at every time of any series: (len(times), n_series, 3)
        table_k = np.stack(
            [Kv[np.maximum(np.searchsorted(tv, times, side="right") - 1, 0)]
             for tv, Kv in series.values()], axis=1)
        n = len(series) if table.vehicle is not None else None

        def schedule(obs: Observation) -> Array:
            i = max(int(np.searchsorted(times, obs.t + 1e-9, side="right")) - 1, 0)
            if n is not None and obs.gap.shape[-1] != n:
                raise StringStabError(
                    f"{src}: has gain series for followers 1..{n}; the platoon has "
                    f"{obs.gap.shape[-1]} followers: expected {n}"
                )
            return table_k[i] if n is not None else table_k[i, 0]

        ctrl = cls(schedule, headway=headway, standstill=standstill)
        ctrl.followers = n
        return ctrl

    @property
    def headway(self) -> float:
        """T* of the eq-3 spacing policy, s (the ``headway`` given at construction)."""
        return self._headway

    def gains(self, obs: Observation) -> Array:
        """The gains in force at ``obs.step`` (computed once per step and cached).

        Parameters
        ----------
        obs : Observation
            The current step.

        Returns
        -------
        array (..., 3)
            The schedule's row for the step (the last row after the end), or the callable's
            output.

        Raises
        ------
        StringStabError
            If the callable does not return an array with a last axis of 3.
        """
        if self._last is not None and self._last[0] == obs.step:
            return self._last[1]
        if self._fn is not None:
            K = np.asarray(self._fn(obs), dtype=np.float64)
            if K.shape[-1:] != (3,):
                raise StringStabError(f"a gain policy must return (..., 3) arrays; got shape {K.shape}")
        else:
            assert self._table is not None
            K = self._table[min(obs.step, self._table.shape[0] - 1)]
        self._last = (obs.step, K)
        return K

    def command(self, obs: Observation) -> Array:
        """The eq-4 law with the gains in force (:meth:`gains`).

        Parameters
        ----------
        obs : Observation
            What every follower knows at this step.

        Returns
        -------
        array
            u = k_x (gap − T* v − l_0) + k_v Δv + k_a a_{i−1}(t − δ), m/s².
        """
        return linear_law(self.gains(obs), obs, headway=self._headway,
                          standstill=self.standstill)

    def equilibrium_gap(self, speed: npt.ArrayLike) -> Array:
        """l_0 + T* v (eq 3), whatever the gains.

        Parameters
        ----------
        speed : array_like
            Cruise speed v, m/s.

        Returns
        -------
        array
            The equilibrium gap, m.
        """
        return time_headway_gap(speed, headway=self._headway, standstill=self.standstill)

    def describe(self) -> dict[str, Any]:
        """A JSON-ready description of the law (without the gains, which change over time).

        Returns
        -------
        dict
            ``controller`` (``"time-varying linear"``), ``headway`` T* (s) and ``standstill``
            l_0 (m).
        """
        return {"controller": "time-varying linear", "headway": self._headway,
                "standstill": self.standstill}
