"""Car-following controllers: the IDL linear law (eq 4), time-varying gains, CACC and IDM.

Every controller maps an :class:`Observation` of a batch of followers (arrays of any common
shape, typically ``(n_platoons, n_followers)``) to desired accelerations u (m/s²).  The
simulator (:mod:`stringstab.traffic.platoon`) then limits u to the acceleration bounds and
passes it through the vehicle's actuator lag.

* :class:`LinearController` — the IDL paper's eq 4, u = k_x Δp + k_v Δv + k_a a_{i−1}(t − δ)
  with Δp = gap − (T* v + l_0) (eq 3);
* :class:`TimeVaryingLinearController` — the same law with gains that change over time, from a
  schedule array, a CSV file or a policy callable (the IDL agent outputs K each step, eq 17);
* :class:`CACCController` — the CACC of van Arem, van den Broek & Visser (2006), the IDL
  paper's model-based baseline (§4.1.4), with the predecessor's acceleration received δ late;
* :class:`IDMController` — the Intelligent Driver Model (Treiber, Hennecke & Helbing 2000), a
  stand-in for human-driven followers;
* :class:`FunctionController` — any callable (e.g. a pure-RL acceleration policy);
* :class:`MixedController` — different controllers at different positions of the platoon.

References
----------
.. [IDL] Z. Yi, M. Xu, S. Wang, Transportation Research Part C 184 (2026) 105541, eqs 3-4, 17.
.. [Arem2006] B. van Arem, C. J. G. van Driel, R. Visser, "The impact of cooperative adaptive
   cruise control on traffic-flow characteristics", IEEE Trans. ITS 7(4) (2006) 429-436.
.. [IDM] M. Treiber, A. Hennecke, D. Helbing, "Congested traffic states in empirical
   observations and microscopic simulations", Phys. Rev. E 62 (2000) 1805-1824.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from ..constants import SPEED_MAX, STANDSTILL
from ..errors import StringStabError, show
from ..io.gains import GainTable
from ..params import DEFAULT_HEADWAY, as_gains, positive

__all__ = [
    "DEFAULT_STANDSTILL",
    "CACCController",
    "Controller",
    "FunctionController",
    "IDMController",
    "LinearController",
    "MixedController",
    "Observation",
    "TimeVaryingLinearController",
    "linear_law",
]

Array = npt.NDArray[np.float64]

#: Standstill spacing l_0, m (IDL paper Table 2).
DEFAULT_STANDSTILL = STANDSTILL


@dataclass(frozen=True, slots=True)
class Observation:
    """What every follower of a batch knows at one step (arrays of one shape).

    Attributes
    ----------
    step : int
        Step index k (t = k·dt).
    t, dt : float
        Time and step, s.
    gap : array
        Bumper-to-bumper distance to the predecessor Δx, m (≤ 0 is a collision).
    speed, accel : array
        The follower's own speed (m/s) and acceleration (m/s²).
    pred_speed : array
        The predecessor's speed, m/s.
    rel_speed : array
        Δv = pred_speed − speed, m/s.
    pred_accel : array
        The predecessor's current acceleration (what a sensor would see), m/s².
    pred_accel_delayed : array
        a_{i−1}(t − δ), the predecessor's acceleration received over the delayed link, m/s².
    """

    step: int
    t: float
    dt: float
    gap: Array
    speed: Array
    accel: Array
    pred_speed: Array
    rel_speed: Array
    pred_accel: Array
    pred_accel_delayed: Array


def linear_law(gains: npt.ArrayLike, obs: Observation, *, headway: float,
               standstill: float = DEFAULT_STANDSTILL) -> Array:
    """The IDL linear law (eqs 3-4) for the gains in force, vectorised over a batch.

    u = k_x (gap − T* v − l_0) + k_v Δv + k_a a_{i−1}(t − δ), the spacing error Δp of eq 3
    inside the eq-4 law, with a gain triple per follower (or one broadcast to all).

    Parameters
    ----------
    gains : array_like, shape (..., 3)
        K = (k_x [1/s²], k_v [1/s], k_a [-]) per follower; the leading axes broadcast against
        ``obs.gap`` (e.g. ``(n, 1, 3)`` for ``n`` platoons of one follower).
    obs : Observation
        What every follower knows at this step.
    headway : float
        Desired time headway T* of eq 3, s.
    standstill : float
        Standstill spacing l_0 of eq 3, m.

    Returns
    -------
    ndarray
        u, m/s², shaped like ``obs.gap`` broadcast with ``gains[..., 0]``, before the
        platoon's limits and actuator lag.

    Examples
    --------
    >>> z = np.zeros(1)
    >>> obs = Observation(0, 0.0, 0.1, gap=np.array([27.0]), speed=np.array([20.0]),
    ...                   accel=z, pred_speed=np.array([21.0]), rel_speed=np.array([1.0]),
    ...                   pred_accel=z, pred_accel_delayed=np.array([0.5]))
    >>> linear_law([1.2, 0.5, 0.6], obs, headway=1.1, standstill=2.0).round(6).tolist()
    [4.4]
    """
    K = np.asarray(gains, dtype=np.float64)
    k_x, k_v, k_a = K[..., 0], K[..., 1], K[..., 2]
    return np.asarray(k_x * (obs.gap - headway * obs.speed - standstill)
                      + k_v * obs.rel_speed + k_a * obs.pred_accel_delayed)


class Controller:
    """Interface of a car-following controller (subclass and override :meth:`command`)."""

    #: True if :meth:`gains` returns a different K at different steps.
    time_varying: bool = False

    def command(self, obs: Observation) -> Array:
        """Desired accelerations u (m/s²), shaped like ``obs.gap``.

        Parameters
        ----------
        obs : Observation
            What every follower knows at this step.

        Returns
        -------
        array
            u per follower, m/s², before the platoon's limits and actuator lag.
        """
        raise NotImplementedError

    def equilibrium_gap(self, speed: npt.ArrayLike) -> Array:
        """The gap (m) where u = 0 for a follower at ``speed`` behind an equal-speed leader.

        It is used to start a platoon in equilibrium.  The base class returns the IDL spacing
        policy l_0 + T* v (eq 3) with the defaults.

        Parameters
        ----------
        speed : array_like
            Cruise speed v, m/s.

        Returns
        -------
        array
            The equilibrium gap, m, shaped like ``speed``.
        """
        return DEFAULT_STANDSTILL + DEFAULT_HEADWAY * np.asarray(speed, dtype=np.float64)

    def gains(self, obs: Observation) -> Array | None:
        """The eq-4 gain vector K = (k_x, k_v, k_a) in force, shape ``(..., 3)``, or None.

        None means the controller is not of the eq-4 form (then M_fss, eq 27, is undefined).

        Parameters
        ----------
        obs : Observation
            The current step (time-varying controllers read ``obs.step`` or the state).

        Returns
        -------
        array (..., 3) or None
            None in the base class.
        """
        return None

    @property
    def headway(self) -> float | None:
        """T* of the equivalent eq-4 law (for the certificate), or None."""
        return None

    def describe(self) -> dict[str, Any]:
        """A JSON-ready description."""
        return {"controller": type(self).__name__}


class LinearController(Controller):
    """The IDL linear law with fixed gains (IDL paper eqs 3-4).

    u = k_x (gap − T* v − l_0) + k_v (v_{i−1} − v) + k_a a_{i−1}(t − δ)

    Parameters
    ----------
    k_x, k_v, k_a : float or array
        Gains; arrays broadcast against the batch (e.g. shape ``(n_followers,)`` for a gain
        per position).
    headway : float
        Desired time headway T*, s (eq 3).
    standstill : float
        Standstill spacing l_0, m (eq 3).

    Examples
    --------
    >>> c = LinearController(1.2, 0.5, 0.6)
    >>> float(c.equilibrium_gap(20.0))
    24.0
    """

    def __init__(self, k_x: npt.ArrayLike, k_v: npt.ArrayLike, k_a: npt.ArrayLike, *,
                 headway: float = DEFAULT_HEADWAY, standstill: float = DEFAULT_STANDSTILL) -> None:
        self.k_x, self.k_v, self.k_a = as_gains(k_x, k_v, k_a)
        self._headway = positive("headway (T*)", headway, allow_zero=True)
        self.standstill = positive("standstill spacing l0", standstill, allow_zero=True)
        self._kxT = self.k_x * self._headway
        self._kxl = self.k_x * self.standstill
        self._K = np.stack([self.k_x, self.k_v, self.k_a], axis=-1)

    @property
    def headway(self) -> float:
        """T* of the eq-3 spacing policy, s (the ``headway`` given at construction)."""
        return self._headway

    def command(self, obs: Observation) -> Array:
        """The eq-4 law u = k_x (gap − T* v − l_0) + k_v Δv + k_a a_{i−1}(t − δ) (IDL eqs 3-4).

        Parameters
        ----------
        obs : Observation
            What every follower knows at this step.

        Returns
        -------
        array
            u, m/s², shaped like ``obs.gap`` (broadcast with the gains).
        """
        u = self.k_x * obs.gap
        u -= self._kxT * obs.speed
        u -= self._kxl
        u += self.k_v * obs.rel_speed
        u += self.k_a * obs.pred_accel_delayed
        return u

    def equilibrium_gap(self, speed: npt.ArrayLike) -> Array:
        """l_0 + T* v, the eq-3 spacing at which u = 0 behind an equal-speed leader.

        Parameters
        ----------
        speed : array_like
            Cruise speed v, m/s.

        Returns
        -------
        array
            The equilibrium gap, m.
        """
        return self.standstill + self._headway * np.asarray(speed, dtype=np.float64)

    def gains(self, obs: Observation) -> Array:
        """The fixed gains.

        Parameters
        ----------
        obs : Observation
            Ignored.

        Returns
        -------
        array (..., 3)
            K = (k_x, k_v, k_a) as given at construction.
        """
        return self._K

    def describe(self) -> dict[str, Any]:
        """A JSON-ready description of the law and its fixed gains.

        Returns
        -------
        dict
            ``controller`` (``"linear"``), the gains ``k_x``, ``k_v``, ``k_a`` (as lists),
            ``headway`` T* (s) and ``standstill`` l_0 (m).
        """
        return {"controller": "linear", "k_x": self.k_x.tolist(), "k_v": self.k_v.tolist(),
                "k_a": self.k_a.tolist(), "headway": self._headway, "standstill": self.standstill}


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
        from ..io import read_gains

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
        return self.standstill + self._headway * np.asarray(speed, dtype=np.float64)

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


class CACCController(Controller):
    """The CACC of van Arem et al. (2006), the IDL paper's model-based baseline (§4.1.4).

    u = min(a_v, a_d), a_v = k (v_int − v),
    a_d = k_a a_{i−1}(t − δ) + k_v (v_{i−1} − v) + k_d (gap − r_ref),
    r_ref = max(r_min, t_system v).

    Their safe distance r_safe = v²/2 (1/d_{i−1} − 1/d_i) vanishes for equal braking
    capabilities and is omitted.  As in the IDL paper, the predecessor's acceleration arrives δ
    late.  In car following (a_d < a_v and t_system v > r_min) this is eq 4 with
    (k_x, k_v, k_a) = (k_d, k_v, k_a) and T* = t_system, which is what :meth:`gains` reports
    for M_fss.

    Parameters
    ----------
    k_a, k_v, k_d, k : float
        Gains; van Arem et al.'s values 1.0, 0.58 s⁻¹, 0.1 s⁻² and 0.3 s⁻¹ by default.
    t_system : float
        Time gap, s.  Van Arem et al. used 0.5 s; the default is the IDL paper's T* = 1.1 s so
        that the baseline and the IDL controller keep the same spacing policy (the IDL paper
        reports 1.44 s mean headway for its CACC, incompatible with 0.5 s).
    r_min : float
        Minimum distance, m.
    speed_intended : float
        Cruise speed v_int of the speed-control mode, m/s (IDL Table 2 v_max).

    Examples
    --------
    >>> CACCController().gains(None).tolist()
    [0.1, 0.58, 1.0]
    """

    def __init__(self, *, k_a: float = 1.0, k_v: float = 0.58, k_d: float = 0.1, k: float = 0.3,
                 t_system: float = DEFAULT_HEADWAY, r_min: float = DEFAULT_STANDSTILL,
                 speed_intended: float = SPEED_MAX) -> None:
        self.k_a, self.k_v, self.k_d, self.k = (float(k_a), float(k_v), float(k_d), float(k))
        self.t_system = positive("t_system", t_system, allow_zero=True)
        self.r_min = positive("r_min", r_min, allow_zero=True)
        self.speed_intended = float(speed_intended)
        self._K = np.array([self.k_d, self.k_v, self.k_a])

    @property
    def headway(self) -> float:
        """T* of the equivalent eq-4 law: the time gap ``t_system``, s."""
        return self.t_system

    def command(self, obs: Observation) -> Array:
        """u = min(a_v, a_d) of van Arem et al. (2006) (see the class docstring).

        Parameters
        ----------
        obs : Observation
            What every follower knows at this step.

        Returns
        -------
        array
            u, m/s²: the smaller of the speed-control and the gap-control accelerations.
        """
        r_ref = np.maximum(self.r_min, self.t_system * obs.speed)
        a_d = (self.k_a * obs.pred_accel_delayed + self.k_v * obs.rel_speed
               + self.k_d * (obs.gap - r_ref))
        return np.minimum(self.k * (self.speed_intended - obs.speed), a_d)

    def equilibrium_gap(self, speed: npt.ArrayLike) -> Array:
        """r_ref = max(r_min, t_system v), the gap where a_d = 0 behind an equal-speed leader.

        Parameters
        ----------
        speed : array_like
            Cruise speed v, m/s.

        Returns
        -------
        array
            The equilibrium gap, m.
        """
        return np.maximum(self.r_min, self.t_system * np.asarray(speed, dtype=np.float64))

    def gains(self, obs: Observation | None) -> Array:
        """(k_d, k_v, k_a): the eq-4 gains of the gap-control mode (with T* = t_system).

        Parameters
        ----------
        obs : Observation or None
            Ignored.

        Returns
        -------
        array (3,)
            K = (k_x, k_v, k_a) = (k_d, k_v, k_a).  It holds only in car following
            (a_d < a_v and t_system v > r_min), which is not checked.
        """
        return self._K

    def describe(self) -> dict[str, Any]:
        """A JSON-ready description of the CACC and its parameters.

        Returns
        -------
        dict
            ``controller`` (``"cacc (van Arem et al. 2006)"``), the gains ``k_a``, ``k_v``,
            ``k_d``, ``k``, ``t_system`` (s), ``r_min`` (m) and ``speed_intended`` (m/s).
        """
        return {"controller": "cacc (van Arem et al. 2006)", "k_a": self.k_a, "k_v": self.k_v,
                "k_d": self.k_d, "k": self.k, "t_system": self.t_system, "r_min": self.r_min,
                "speed_intended": self.speed_intended}


class IDMController(Controller):
    """The Intelligent Driver Model (Treiber et al. 2000), a human-driver stand-in.

    u = a [1 − (v/v_0)^4 − (s*/s)²],  s* = s_0 + max(0, v T + v (v − v_{i−1}) / (2√(a b))).

    Human drivers receive no communicated acceleration.  The defaults are the highway values
    of Treiber et al. (2000), Table 1: v_0 = 120 km/h (here the IDL v_max 33.3 m/s), T = 1.6 s,
    s_0 = 2 m, a = 0.73 m/s², b = 1.67 m/s².  The gap in the formula is floored at 1 cm so u
    stays finite during a collision (which the simulator still reports).

    Examples
    --------
    >>> round(float(IDMController().equilibrium_gap(20.0)), 2)
    36.45
    """

    def __init__(self, *, desired_speed: float = SPEED_MAX, time_headway: float = 1.6,
                 min_gap: float = STANDSTILL, max_accel: float = 0.73, comfortable_decel: float = 1.67,
                 exponent: float = 4.0) -> None:
        self.v0 = positive("desired_speed", desired_speed)
        self.T = positive("time_headway", time_headway, allow_zero=True)
        self.s0 = positive("min_gap", min_gap, allow_zero=True)
        self.a = positive("max_accel", max_accel)
        self.b = positive("comfortable_decel", comfortable_decel)
        self.exponent = positive("exponent", exponent)
        self._ab2 = 2.0 * math.sqrt(self.a * self.b)

    def command(self, obs: Observation) -> Array:
        """The IDM acceleration u = a [1 − (v/v_0)^exponent − (s*/s)²] (Treiber et al. 2000).

        Parameters
        ----------
        obs : Observation
            What every follower knows at this step (the delayed predecessor acceleration is not
            used).

        Returns
        -------
        array
            u, m/s² (the gap s floored at 1 cm).
        """
        v = obs.speed
        s_star = self.s0 + np.maximum(0.0, v * self.T - v * obs.rel_speed / self._ab2)
        s = np.maximum(obs.gap, 0.01)
        return self.a * (1.0 - (v / self.v0) ** self.exponent - (s_star / s) ** 2)

    def equilibrium_gap(self, speed: npt.ArrayLike) -> Array:
        """s_e = (s_0 + v T) / sqrt(1 − (v/v_0)^exponent), where u = 0 behind an equal-speed leader.

        Parameters
        ----------
        speed : array_like
            Cruise speed v, m/s (capped at 0.999 v_0, where the gap is still finite).

        Returns
        -------
        array
            The equilibrium gap, m.
        """
        v = np.minimum(np.asarray(speed, dtype=np.float64), 0.999 * self.v0)
        return (self.s0 + v * self.T) / np.sqrt(1.0 - (v / self.v0) ** self.exponent)

    def describe(self) -> dict[str, Any]:
        """A JSON-ready description of the IDM and its parameters.

        Returns
        -------
        dict
            ``controller`` (``"idm (Treiber et al. 2000)"``), ``desired_speed`` v_0 (m/s),
            ``time_headway`` T (s), ``min_gap`` s_0 (m), ``max_accel`` a and
            ``comfortable_decel`` b (m/s²) and ``exponent``.
        """
        return {"controller": "idm (Treiber et al. 2000)", "desired_speed": self.v0,
                "time_headway": self.T, "min_gap": self.s0, "max_accel": self.a,
                "comfortable_decel": self.b, "exponent": self.exponent}


class FunctionController(Controller):
    """A controller from a callable ``fn(obs) -> u`` (e.g. a pure-RL acceleration policy).

    Parameters
    ----------
    fn : callable
        Returns desired accelerations shaped like ``obs.gap``.
    headway, standstill : float
        The equilibrium spacing policy used to start a platoon (l_0 + T* v).
    """

    def __init__(self, fn: Callable[[Observation], npt.ArrayLike], *,
                 headway: float = DEFAULT_HEADWAY, standstill: float = DEFAULT_STANDSTILL) -> None:
        self.fn = fn
        self._headway, self.standstill = float(headway), float(standstill)

    def command(self, obs: Observation) -> Array:
        """``fn(obs)``, broadcast to the shape of ``obs.gap``.

        Parameters
        ----------
        obs : Observation
            What every follower knows at this step.

        Returns
        -------
        array
            u, m/s² (a copy).
        """
        return np.broadcast_to(np.asarray(self.fn(obs), dtype=np.float64), obs.gap.shape).copy()

    def equilibrium_gap(self, speed: npt.ArrayLike) -> Array:
        """l_0 + T* v with the ``headway`` and ``standstill`` given.

        Parameters
        ----------
        speed : array_like
            Cruise speed v, m/s.

        Returns
        -------
        array
            The gap a platoon starts with, m.
        """
        return self.standstill + self._headway * np.asarray(speed, dtype=np.float64)


class MixedController(Controller):
    """Different controllers at different platoon positions (e.g. IDM humans among CAVs).

    Every candidate is evaluated on the whole batch and the results are selected per position,
    so the cost is the sum of the candidates'.  :meth:`gains` returns K only if every candidate
    is of the eq-4 form with one headway.

    Parameters
    ----------
    controllers : sequence of Controller
        The candidates.
    assignment : sequence of int
        For each follower position (1..N), the index of its controller.
    """

    def __init__(self, controllers: Sequence[Controller], assignment: Sequence[int]) -> None:
        self.controllers = list(controllers)
        self.assignment = np.asarray(assignment, dtype=np.int64)
        if self.assignment.ndim != 1 or not self.controllers:
            raise StringStabError("MixedController needs controllers and a 1-D assignment per position")
        if (self.assignment < 0).any() or (self.assignment >= len(self.controllers)).any():
            raise StringStabError(
                f"assignment indices must be in [0, {len(self.controllers) - 1}]; got {self.assignment.tolist()}"
            )
        self.time_varying = any(c.time_varying for c in self.controllers)

    def command(self, obs: Observation) -> Array:
        """Each follower position's own controller's command.

        Parameters
        ----------
        obs : Observation
            What every follower knows at this step (last axis: the N follower positions).

        Returns
        -------
        array
            u, m/s², shaped like ``obs.gap``.
        """
        return np.asarray(np.choose(self.assignment, [c.command(obs) for c in self.controllers]))

    def equilibrium_gap(self, speed: npt.ArrayLike) -> Array:
        """Each follower position's own controller's equilibrium gap.

        Parameters
        ----------
        speed : array_like
            Cruise speed v, m/s (broadcast against the N positions).

        Returns
        -------
        array (..., N)
            The equilibrium gaps, m.
        """
        v = np.asarray(speed, dtype=np.float64)
        shape = np.broadcast_shapes(v.shape, (self.assignment.size,))
        gaps = [np.broadcast_to(c.equilibrium_gap(v), shape) for c in self.controllers]
        return np.asarray(np.choose(self.assignment, gaps))

    @property
    def headway(self) -> float | None:
        """The candidates' common T*, s, or None if they differ or one of them has none."""
        hs = {c.headway for c in self.controllers}
        return hs.pop() if len(hs) == 1 else None

    def gains(self, obs: Observation) -> Array | None:
        """Each position's eq-4 gains, if every candidate is of the eq-4 form with one headway.

        Parameters
        ----------
        obs : Observation
            The current step.

        Returns
        -------
        array (..., N, 3) or None
            The gains per follower, or None if a candidate has none or the headways differ.
        """
        gs = [c.gains(obs) for c in self.controllers]
        if any(g is None for g in gs) or self.headway is None:
            return None
        shape = (*obs.gap.shape, 3)
        stacked = [np.broadcast_to(g, shape) for g in gs if g is not None]
        return np.asarray(np.choose(self.assignment[:, None], stacked))
