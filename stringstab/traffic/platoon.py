"""Platoon dynamics: N followers behind a prescribed leader, many platoons at once.

Each follower i obeys the IDL paper's third-order model (eqs 5-7)

    ẋ_i = v_i,   v̇_i = a_i,   τ ȧ_i = −a_i + u_i,

with u_i from a controller (:mod:`~stringstab.traffic.controllers`) that sees the predecessor's
acceleration δ seconds late (eq 4).  All followers of all platoons advance together: the state
is a set of ``(n_platoons, n_followers + 1)`` arrays whose column 0 is the leader.

Discretisation (``model="lag"``, the default)
    u is held constant over each step (zero-order hold) and eqs 5-7 are integrated *exactly*
    over the step: with e = exp(−Δt/τ) and ā = a_k − u_k,

        a_{k+1} = u_k + ā e,
        v_{k+1} = v_k + u_k Δt + ā τ (1 − e),
        x_{k+1} = x_k + v_k Δt + u_k Δt²/2 + ā τ (Δt − τ (1 − e)).

    This is stable and exact for every Δt/τ (forward Euler on the lag, a_{k+1} = a_k +
    Δt (u_k − a_k)/τ, is only first-order accurate and oscillates for Δt > τ).  The only
    discretisation error left is the hold itself: the continuous loop is closed through a
    sampler, which acts like an extra delay of about Δt/2.

Communication delay δ
    Every step stores all vehicles' accelerations (and commands) in a ring buffer.  With
    δ/Δt = n + f (n integer, 0 ≤ f < 1) the received value is, by default
    (``fractional_delay="linear"``), the linear interpolation (1 − f) a(t_{k−n}) + f a(t_{k−n−1}),
    i.e. a(t_k − δ) to second order; it is exact when δ is a multiple of Δt (f = 0).  With
    ``fractional_delay="exact"`` it is the predecessor's acceleration at t_k − δ itself, as its
    model evolves inside the step: u + (a − u) e^{−(1−f)Δt/τ_p} from the sample and the held
    command of step k − n − 1 (``model="lag"``; the held command u itself with
    ``model="kinematic"``), which is the sampled-data loop :mod:`stringstab.certify.sampled` certifies.
    The leader's acceleration between samples is not modelled, so its followers receive the
    interpolation either way.  Before t = 0 the history is the initial acceleration.

``position_update="trapezoid"``
    With ``model="lag"``, positions advance by the trapezoid rule on the step's speeds,
    x_{k+1} = x_k + Δt (v_k + v_{k+1})/2, instead of the exact integral above (speeds and
    accelerations are unchanged).  This is Eclipse SUMO's ballistic position update
    (``--step-method.ballistic``), so a run with it is the one :mod:`stringstab.sumo` co-simulates;
    the difference from the exact integral is ā (τ(Δt − τ(1 − e)) − τ(1 − e)Δt/2) per step, of
    order ā Δt³/(12 τ).

``model="kinematic"``
    The paper's simpler update (eqs 1-2): no lag, a_k = u_k (limited), v_{k+1} = v_k + a_k Δt,
    and positions by the trapezoid rule, which is exactly the spacing update of eq 2.

Limits
    u is limited to [acc_min, acc_max] = [−7.6, 3] m/s² before the lag (so a stays within it
    too), and v to [0, 33.3] m/s (IDL paper Table 2).  When a speed bound is reached inside a
    step, v is set to the bound, the acceleration is cut to 0 in the offending direction (a
    stopped car does not keep braking) and the step's displacement uses the trapezoid rule.

Collisions
    A gap ≤ 0 (bumper to bumper) is a collision.  It is detected at every step, counted (one
    event per entry into a collision) and reported with its first time; positions are *never*
    corrected, so the vehicles overlap in the output just as the dynamics say.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
import numpy.typing as npt

from ..constants import ACCEL_MAX, ACCEL_MIN, SPEED_MAX, TTC_STAR
from ..errors import StringStabError, show
from ..params import DEFAULT_DELTA, DEFAULT_TAU, count
from .controllers import Controller, Observation
from .metrics import damping_ratios_from_energy, platoon_metrics, time_headway
from .trajectory import Trajectory

__all__ = ["DEFAULT_LENGTH", "Limits", "Platoon", "PlatoonResult", "check_leader", "simulate"]

Array = npt.NDArray[np.float64]

#: Vehicle length, m (front bumper to rear bumper); only offsets positions.
DEFAULT_LENGTH = 5.0

Model = Literal["lag", "kinematic"]
FractionalDelay = Literal["linear", "exact"]
PositionUpdate = Literal["exact", "trapezoid"]


@dataclass(frozen=True)
class Limits:
    """Acceleration and speed bounds (IDL paper Table 2).

    Examples
    --------
    >>> Limits()
    Limits(accel_min=-7.6, accel_max=3.0, speed_min=0.0, speed_max=33.3)
    """

    accel_min: float = ACCEL_MIN
    accel_max: float = ACCEL_MAX
    speed_min: float = 0.0
    speed_max: float = SPEED_MAX

    def __post_init__(self) -> None:
        vals = (self.accel_min, self.accel_max, self.speed_min, self.speed_max)
        if not all(isinstance(v, (int, float)) and math.isfinite(v) for v in vals):
            raise StringStabError(f"limits must be finite numbers; got {vals}")
        if not (self.accel_min < 0 < self.accel_max):
            raise StringStabError(
                f"acceleration limits must satisfy accel_min < 0 < accel_max; got "
                f"[{self.accel_min}, {self.accel_max}]"
            )
        if not (0 <= self.speed_min < self.speed_max):
            raise StringStabError(
                f"speed limits must satisfy 0 <= speed_min < speed_max; got [{self.speed_min}, {self.speed_max}]"
            )
        from ..ranges import LEADER_ACCEL_ABSURD, LEADER_SPEED_ABSURD

        if self.speed_max > LEADER_SPEED_ABSURD or max(-self.accel_min, self.accel_max) > LEADER_ACCEL_ABSURD:
            raise StringStabError(
                f"limits beyond any road vehicle: expected speed_max <= {LEADER_SPEED_ABSURD:g} m/s "
                f"and accelerations within ±{LEADER_ACCEL_ABSURD:g} m/s²; got speed_max "
                f"{self.speed_max:g}, [{self.accel_min:g}, {self.accel_max:g}]")


def check_leader(leader: Trajectory, limits: Limits | None = None) -> list[str]:
    """The one leader check of every command that simulates: refuse the absurd, warn the rest.

    A leader faster than :data:`~stringstab.ranges.LEADER_SPEED_ABSURD` (70 m/s) or
    accelerating beyond ±:data:`~stringstab.ranges.LEADER_ACCEL_ABSURD` (15 m/s²) is no road
    vehicle and is refused.  A leader beyond the followers' limits is run with a warning: above
    v_max they saturate there and the gap opens while the leader stays faster (spacing, TTC, m_p
    and M_lss describe the limit as well as the controller); beyond [acc_min, acc_max] their
    commands are limited, so they cannot match it there.

    Parameters
    ----------
    leader : Trajectory
        The leader's speed and acceleration samples.
    limits : Limits, optional
        The followers' limits (default: IDL Table 2).

    Returns
    -------
    list of str
        Warnings, one sentence each (empty when the leader is within every limit).

    Raises
    ------
    StringStabError
        If the leader is physically absurd (speed > 70 m/s or |acceleration| > 15 m/s²).

    Examples
    --------
    >>> from stringstab.traffic.trajectory import from_speed
    >>> print(*check_leader(from_speed([0, 1], [20.0, 25.0], dt=0.1)))
    the leader accelerates at up to 5 m/s², beyond the followers' limit acc_max = 3 m/s² (first at t = 0 s): they cannot match it there, so the metrics measure the limits as well as the controller
    >>> print(*check_leader(from_speed([0, 10, 20], [30.0, 34.7, 34.7], dt=0.1)))
    the leader reaches 34.7 m/s at t = 7.1 s, above the followers' speed limit v_max = 33.3 m/s (IDL Table 2; --v-max raises it): they saturate there and the gap opens, so the metrics measure the limit as well as the controller
    """
    from ..ranges import LEADER_ACCEL_ABSURD, LEADER_SPEED_ABSURD

    lim = limits or Limits()
    v, a = leader.speed, leader.accel
    k = int(np.argmax(v))
    if v[k] > LEADER_SPEED_ABSURD:
        raise StringStabError(
            f"leader {show(leader.name)} reaches {float(v[k]):.4g} m/s at t = {k * leader.dt:.4g} s: "
            f"no road vehicle; expected a leader within [0, {LEADER_SPEED_ABSURD:g}] m/s "
            f"(the followers' limit is v_max = {lim.speed_max:g} m/s)")
    ka = int(np.argmax(np.abs(a))) if a.size else 0
    if a.size and abs(float(a[ka])) > LEADER_ACCEL_ABSURD:
        raise StringStabError(
            f"leader {show(leader.name)} accelerates at {float(a[ka]):.4g} m/s² at t = "
            f"{ka * leader.dt:.4g} s: no road vehicle; expected accelerations within "
            f"±{LEADER_ACCEL_ABSURD:g} m/s²")
    warnings = []
    if v[k] > lim.speed_max + 1e-9:
        first = int(np.argmax(v > lim.speed_max + 1e-9)) * leader.dt
        table2 = " (IDL Table 2; --v-max raises it)" if lim.speed_max == SPEED_MAX else ""
        warnings.append(
            f"the leader reaches {float(v[k]):.4g} m/s at t = {first:.4g} s, above the followers' "
            f"speed limit v_max = {lim.speed_max:g} m/s{table2}: they saturate there and the gap "
            "opens, so the metrics measure the limit as well as the controller")
    for side, bound, beyond in (("max", lim.accel_max, a > lim.accel_max + 1e-9),
                                ("min", lim.accel_min, a < lim.accel_min - 1e-9)):
        if beyond.any():
            peak = float(a.max() if side == "max" else a.min())
            first = int(np.argmax(beyond)) * leader.dt
            word = "accelerates" if side == "max" else "brakes"
            warnings.append(
                f"the leader {word} at up to {abs(peak):.4g} m/s², beyond the followers' limit "
                f"acc_{side} = {bound:g} m/s² (first at t = {first:.4g} s): they cannot match "
                "it there, so the metrics measure the limits as well as the controller"
            )
    return warnings


def _check_lag_delay(tau: npt.ArrayLike, delta: float) -> tuple[Array, float]:
    try:
        t = np.asarray(tau, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise StringStabError(f"tau (actuator lag) must be a number > 0 s; got {show(tau)}") from e
    if not (np.isfinite(t).all() and (t > 0).all()):
        raise StringStabError(f"tau (actuator lag) must be a finite number > 0 s; got {show(tau)}")
    try:
        d = float(delta)
    except (TypeError, ValueError) as e:
        raise StringStabError(f"delta (communication delay) must be a number >= 0 s; got {show(delta)}") from e
    if not (math.isfinite(d) and d >= 0):
        raise StringStabError(f"delta (communication delay) must be a finite number >= 0 s; got {show(delta)}")
    return t, d


class Platoon:
    """The stepping core: ``n_platoons`` platoons of ``n_followers`` followers each.

    Use :func:`simulate` for whole runs; this class is the building block of the simulator and
    of the Gymnasium environments (:mod:`stringstab.traffic.env`).  A step is
    ``obs = observe(leader state at k)`` → controller → ``advance(u)``.

    Parameters
    ----------
    n_platoons, n_followers : int
        Batch size P and platoon size N.
    dt : float
        Step Δt, s.
    tau : float or array
        Actuator lag τ, s (> 0); an array broadcasts against ``(P, N)``.
    delta : float
        Communication delay δ, s (≥ 0).
    model : {"lag", "kinematic"}
        Third-order model with exact ZOH (eqs 5-7) or the paper's kinematic update (eqs 1-2).
    limits : Limits
        Acceleration and speed bounds.
    length : float
        Vehicle length, m (gap = x_{i−1} − x_i − length).
    fractional_delay : {"linear", "exact"}
        How a delay that is not a multiple of Δt is received: interpolated linearly between
        samples (default), or the predecessor's exact acceleration inside the step (the
        module docstring).
    position_update : {"exact", "trapezoid"}
        With ``model="lag"``: the exact integral of the speed over the step (default) or the
        trapezoid rule, SUMO's ballistic update (the module docstring).

    Attributes
    ----------
    position, speed, accel : array (P, N + 1)
        Current state; column 0 is the leader.
    step : int
        Steps taken since construction.
    collided : bool array (P, N)
        Whether a follower has ever been in collision.
    collision_events : int array (P, N)
        Number of entries into a collision.
    first_collision_step : int array (P, N)
        Step of the first collision, −1 if none.
    """

    def __init__(self, n_platoons: int, n_followers: int, *, dt: float, tau: npt.ArrayLike = DEFAULT_TAU,
                 delta: float = DEFAULT_DELTA, model: Model = "lag", limits: Limits | None = None,
                 length: float = DEFAULT_LENGTH, fractional_delay: FractionalDelay = "linear",
                 position_update: PositionUpdate = "exact") -> None:
        if int(n_platoons) < 1 or int(n_followers) < 1:
            raise StringStabError(
                f"n_platoons and n_followers must be >= 1; got {show(n_platoons)} and {show(n_followers)}"
            )
        if not (isinstance(dt, (int, float)) and math.isfinite(dt) and dt > 0):
            raise StringStabError(f"dt must be a finite number > 0 s; got {show(dt)}")
        if model not in ("lag", "kinematic"):
            raise StringStabError(f"model must be 'lag' or 'kinematic'; got {show(model)}")
        if fractional_delay not in ("linear", "exact"):
            raise StringStabError(
                f"fractional_delay must be 'linear' or 'exact'; got {show(fractional_delay)}")
        if position_update not in ("exact", "trapezoid"):
            raise StringStabError(
                f"position_update must be 'exact' or 'trapezoid'; got {show(position_update)}")
        tau_arr, d = _check_lag_delay(tau, delta)
        self.position_update = position_update
        P, N = int(n_platoons), int(n_followers)
        self.P, self.N, self.dt, self.model, self.delta = P, N, float(dt), model, d
        self.limits = limits or Limits()
        self.length = float(length)
        try:
            tau_b = np.broadcast_to(tau_arr, (P, N))
        except ValueError as e:
            raise StringStabError(f"tau must broadcast to (n_platoons, n_followers)=({P}, {N}); got shape {tau_arr.shape}") from e
        self.tau = tau_arr
        decay = np.exp(-self.dt / tau_b)
        scalar = tau_arr.ndim == 0
        self._e: float | Array = float(decay[0, 0]) if scalar else np.ascontiguousarray(decay)
        c1 = tau_b * (1.0 - decay)
        c2 = tau_b * (self.dt - c1)
        self._c1 = float(c1[0, 0]) if scalar else np.ascontiguousarray(c1)
        self._c2 = float(c2[0, 0]) if scalar else np.ascontiguousarray(c2)
        q = d / self.dt
        n = math.floor(q + 1e-9)
        f = q - n
        if f < 1e-9:
            f = 0.0
        self._n_delay, self._frac = n, f
        self.fractional_delay = fractional_delay
        # the exact fractional delay: a_p(t_j + (1 − f)Δt) = u_j + (a_j − u_j) C, C per receiver
        # (its predecessor's lag; 0 for the kinematic model, whose a is the held u in a step)
        self._exact_frac = fractional_delay == "exact" and f > 0.0
        C = np.zeros((P, N))
        if model == "lag":
            C[:, 1:] = np.exp(-(1.0 - f) * self.dt / tau_b[:, :-1])
        self._frac_c = C
        self._ring = n + 2
        self.position = np.zeros((P, N + 1))
        self.speed = np.zeros((P, N + 1))
        self.accel = np.zeros((P, N + 1))
        self._buf = np.zeros((self._ring, P, N + 1))
        self._ubuf = np.zeros((self._ring, P, N + 1))  # held commands (the exact fractional delay)
        self.step = 0
        self.collided = np.zeros((P, N), dtype=bool)
        self.collision_events = np.zeros((P, N), dtype=np.int64)
        self.first_collision_step = np.full((P, N), -1, dtype=np.int64)
        self._in_collision = np.zeros((P, N), dtype=bool)
        self._any_in_collision = False

    def reset(self, leader_position: npt.ArrayLike, leader_speed: npt.ArrayLike,
              leader_accel: npt.ArrayLike, *, gap: npt.ArrayLike, speed: npt.ArrayLike,
              accel: npt.ArrayLike = 0.0, rows: npt.ArrayLike | None = None) -> None:
        """Place the followers of ``rows`` (default all) behind their leaders.

        Parameters
        ----------
        leader_position, leader_speed, leader_accel : array (P,) or (len(rows),)
            Leader state.
        gap, speed, accel : array broadcastable to (P or len(rows), N)
            Followers' initial gaps (m), speeds (m/s) and accelerations (m/s²).  The delay
            buffer of those rows is filled with these accelerations (constant history).
        rows : index array, optional
            Platoons to reset.
        """
        r: Any = slice(None) if rows is None else np.asarray(rows)
        m = self.P if rows is None else int(np.asarray(rows).size)
        g = np.broadcast_to(np.asarray(gap, dtype=np.float64), (m, self.N))
        if not np.isfinite(g).all():
            raise StringStabError("initial gaps must be finite")
        X = np.empty((m, self.N + 1))
        X[:, 0] = leader_position
        X[:, 1:] = -np.cumsum(g + self.length, axis=1)
        X[:, 1:] += X[:, :1]
        V = np.empty((m, self.N + 1))
        V[:, 0] = leader_speed
        V[:, 1:] = np.broadcast_to(np.asarray(speed, dtype=np.float64), (m, self.N))
        A = np.empty((m, self.N + 1))
        A[:, 0] = leader_accel
        A[:, 1:] = np.broadcast_to(np.asarray(accel, dtype=np.float64), (m, self.N))
        self.position[r] = X
        self.speed[r] = V
        self.accel[r] = A
        self._buf[:, r] = A
        self._ubuf[:, r] = A  # a constant history: a = u
        self.collided[r] = False
        self.collision_events[r] = 0
        self.first_collision_step[r] = -1
        self._in_collision[r] = False
        self._any_in_collision = bool(self._in_collision.any())

    def observe(self, leader_position: npt.ArrayLike, leader_speed: npt.ArrayLike,
                leader_accel: npt.ArrayLike) -> Observation:
        """Set the leaders' state at the current step and return what the followers know.

        Also records collisions (gap ≤ 0) and stores accelerations for the delayed link.  The
        observation's arrays may be views of the state: they are valid until :meth:`advance`.
        A delay δ that is not a multiple of the step is interpolated between the two samples
        around t − δ.

        Parameters
        ----------
        leader_position : array_like (P,)
            Position of each platoon's leader at this step, m.
        leader_speed : array_like (P,)
            Its speed, m/s.
        leader_accel : array_like (P,)
            Its acceleration, m/s².

        Returns
        -------
        Observation
            Arrays (P, N): gap Δx (m), speed, acceleration, the predecessor's speed, Δv,
            the predecessor's acceleration and a_{i−1}(t − δ) (IDL eq 4).
        """
        X, V, A = self.position, self.speed, self.accel
        X[:, 0] = leader_position
        V[:, 0] = leader_speed
        A[:, 0] = leader_accel
        k = self.step
        self._buf[k % self._ring] = A
        gap = X[:, :-1] - X[:, 1:]
        gap -= self.length
        rel = V[:, :-1] - V[:, 1:]
        ad = self._buf[(k - self._n_delay) % self._ring][:, :-1]
        if self._frac:
            older = self._buf[(k - self._n_delay - 1) % self._ring][:, :-1]
            lead = (1.0 - self._frac) * ad[:, 0] + self._frac * older[:, 0]
            if self._exact_frac:
                u_old = self._ubuf[(k - self._n_delay - 1) % self._ring][:, :-1]
                ad = u_old + (older - u_old) * self._frac_c
                ad[:, 0] = lead  # the leader's acceleration between samples is not modelled
            else:
                ad = ad * (1.0 - self._frac)
                ad += self._frac * older
        coll = gap <= 0.0
        if self._any_in_collision or coll.any():
            new = coll & ~self._in_collision
            if new.any():
                self.collision_events += new
                first = new & ~self.collided
                self.first_collision_step[first] = k
                self.collided |= new
            self._in_collision = coll
            self._any_in_collision = bool(coll.any())
        return Observation(k, k * self.dt, self.dt, gap, V[:, 1:], A[:, 1:], V[:, :-1], rel,
                           A[:, :-1], ad)

    def advance(self, command: npt.ArrayLike) -> Array:
        """Apply desired accelerations u (P, N) over one step; returns the limited u.

        u is clipped to [acc_min, acc_max]; with ``model="lag"`` the acceleration follows
        τ ȧ + a = u (IDL eq 7) exactly over the step (u held), with ``"kinematic"`` a = u.  Speeds are kept
        within the limits (the position then follows the clipped speed).

        Parameters
        ----------
        command : array_like, broadcastable to (P, N)
            Desired accelerations u of the followers, m/s².

        Returns
        -------
        ndarray (P, N)
            The commands applied after the acceleration limits, m/s².
        """
        lim = self.limits
        u = np.clip(np.asarray(command, dtype=np.float64), lim.accel_min, lim.accel_max)
        if u.shape != (self.P, self.N):
            u = np.ascontiguousarray(np.broadcast_to(u, (self.P, self.N)))
        dt = self.dt
        xo, vo, ao = self.position[:, 1:], self.speed[:, 1:], self.accel[:, 1:]
        if self.model == "lag":
            du = ao - u
            xn = vo * dt
            xn += xo
            xn += u * (0.5 * dt * dt)
            xn += du * self._c2
            vn = u * dt
            vn += vo
            vn += du * self._c1
            an = du * self._e
            an += u
            if self.position_update == "trapezoid":
                xn = vo + vn
                xn *= 0.5 * dt
                xn += xo
        else:
            an = u
            vn = u * dt
            vn += vo
            xn = vo + vn
            xn *= 0.5 * dt
            xn += xo
        if vn.min() < lim.speed_min or vn.max() > lim.speed_max:
            lo = vn < lim.speed_min
            hi = vn > lim.speed_max
            vc = np.clip(vn, lim.speed_min, lim.speed_max)
            xn = np.where(lo | hi, xo + 0.5 * dt * (vo + vc), xn)
            if self.model == "lag":
                an = np.where(lo, np.maximum(an, 0.0), np.where(hi, np.minimum(an, 0.0), an))
            else:
                an = (vc - vo) / dt
            vn = vc
        xo[...] = xn
        vo[...] = vn
        ao[...] = an
        if self._exact_frac:
            self._ubuf[self.step % self._ring][:, 1:] = u
        self.step += 1
        return u


@dataclass
class PlatoonResult:
    """A simulated run.  Vehicle axis: 0 is the leader, 1..N the followers.

    Shapes below are for a batch of platoons ``(P, ...)``; for a single leader trajectory the
    leading ``P`` axis is dropped.

    Attributes
    ----------
    dt : float
        Step, s.
    t : array (T,)
        Sample times, s.
    position, speed, accel : array (P, N + 1, T) or None
        Recorded states (None when ``record=False``).
    command : array (P, N, T) or None
        Limited desired accelerations u.
    gains : array (P, N, T, 3) or (P, N, 1, 3) or None
        The eq-4 gains in force (one column when constant); None if the controller is not of
        the eq-4 form, or is time-varying and the run was not recorded.
    collided : bool array (P, N)
        Followers that ever had gap ≤ 0.
    collision_events : int array (P, N)
        Entries into a collision.
    first_collision_time : array (P, N)
        Time of the first collision, s (NaN if none).
    min_gap : array (P, N)
        Smallest gap over the run, m.
    sum_sq_accel : array (P, N + 1)
        Σ_t a_i(t)² (for m_p, eq 29).
    params : dict
        τ, δ, T*, model, limits, length, controller.
    """

    dt: float
    t: Array
    position: Array | None
    speed: Array | None
    accel: Array | None
    command: Array | None
    gains: Array | None
    collided: npt.NDArray[np.bool_]
    collision_events: npt.NDArray[np.int64]
    first_collision_time: Array
    min_gap: Array
    sum_sq_accel: Array
    params: dict[str, Any] = field(default_factory=dict)
    length: float = DEFAULT_LENGTH

    @property
    def n_followers(self) -> int:
        """Platoon size N."""
        return int(self.collided.shape[-1])

    def _need(self, name: str) -> Array:
        a = getattr(self, name)
        if a is None:
            raise StringStabError(f"{name} was not recorded; run simulate(..., record=True)")
        return a

    @property
    def gap(self) -> Array:
        """Bumper-to-bumper gaps (P, N, T), m."""
        x = self._need("position")
        return x[..., :-1, :] - x[..., 1:, :] - self.length

    @property
    def headway(self) -> Array:
        """Time headway h (eq 22) of each follower (P, N, T), s; NaN at standstill."""
        return time_headway(self.gap, self._need("speed")[..., 1:, :])

    @property
    def damping_ratios(self) -> Array:
        """m_p of each follower relative to its predecessor (eq 29, intended form), (P, N)."""
        return damping_ratios_from_energy(self.sum_sq_accel)

    def metrics(self, *, ttc_star: float = TTC_STAR, certificate: bool = True) -> dict[str, Any]:
        """The IDL paper's evaluation metrics of this run (see :func:`stringstab.traffic.metrics.platoon_metrics`).

        Parameters
        ----------
        ttc_star : float
            TTC* of the time-integrated TTC (eqs 31-32), s.
        certificate : bool
            Also compute m_fss (eq 27) of the executed gains with the exact certificate.

        Returns
        -------
        dict
            ``m_p`` (eq 29), ``M_lss`` (eq 30), ``TIT``, ``M_CI`` (eq 34), ``M_effi`` (eq 35),
            ``collisions``, ``m_fss`` (eq 27 as a fraction; None without ``certificate``), ...
        """
        return platoon_metrics(self, ttc_star=ttc_star, certificate=certificate)


def _is_trajectory(x: Any) -> bool:
    # duck typing rather than isinstance: a module re-imported (e.g. by doctest collection)
    # defines a second Trajectory class, and user objects with the same fields work too
    return all(hasattr(x, a) for a in ("dt", "position", "speed", "accel", "n_steps"))


def _stack_leaders(leader: Trajectory | Sequence[Trajectory]) -> tuple[list[Trajectory], bool]:
    if _is_trajectory(leader):
        return [leader], False  # type: ignore[list-item]
    try:
        leaders = list(leader)  # type: ignore[arg-type]
    except TypeError:
        leaders = []
    if not leaders or not all(_is_trajectory(tr) for tr in leaders):
        raise StringStabError("leader must be a Trajectory or a non-empty sequence of Trajectory")
    dts = {tr.dt for tr in leaders}
    ns = {tr.n_steps for tr in leaders}
    if len(dts) != 1 or len(ns) != 1:
        raise StringStabError(
            f"batched leaders must share dt and length; got dt {sorted(dts)} and lengths {sorted(ns)}"
        )
    return leaders, True


def simulate(
    leader: Trajectory | Sequence[Trajectory],
    controller: Controller,
    n_followers: int,
    *,
    tau: npt.ArrayLike = DEFAULT_TAU,
    delta: float = DEFAULT_DELTA,
    model: Model = "lag",
    limits: Limits | None = None,
    length: float = DEFAULT_LENGTH,
    initial_gap: npt.ArrayLike | None = None,
    initial_speed: npt.ArrayLike | None = None,
    record: bool = True,
    progress: bool | None = None,
    fractional_delay: FractionalDelay = "linear",
    position_update: PositionUpdate = "exact",
) -> PlatoonResult:
    """Simulate platoons of ``n_followers`` behind prescribed leaders.

    Parameters
    ----------
    leader : Trajectory or sequence of Trajectory
        One leader, or one per platoon (same ``dt`` and length); the step Δt is the leader's.
    controller : Controller
        Computes every follower's desired acceleration (vectorised over the batch).
    n_followers : int
        Followers per platoon N.
    tau : float or array
        Actuator lag τ, s; an array of shape (N,) or (P, N) gives each vehicle its own.
    delta : float
        Communication delay δ on the predecessor's acceleration, s.
    model : {"lag", "kinematic"}
        See :mod:`stringstab.traffic.platoon`.
    limits : Limits, optional
        Acceleration and speed bounds (default IDL Table 2).
    length : float
        Vehicle length, m.
    initial_gap : float or array, optional
        Initial gaps (m); default the controller's equilibrium gap at the leader's initial
        speed, so a platoon starts in equilibrium.
    initial_speed : float or array, optional
        Initial follower speeds (m/s); default the leader's initial speed.
    record : bool
        Keep full trajectories (memory P·(N+1)·T·8 bytes per quantity); if False only the
        summaries (collisions, minimum gaps, Σa² for m_p) are kept.
    progress : bool, optional
        Show a tqdm bar; by default only for long runs (over 10⁸ vehicle-steps).
    fractional_delay : {"linear", "exact"}
        A delay that is not a multiple of Δt: interpolated linearly between received samples
        (default), or the predecessor's exact acceleration inside the step, the loop the
        sampled-data certificate certifies (module docstring; recorded in ``params`` then).
    position_update : {"exact", "trapezoid"}
        Positions by the exact integral of the lag model (default) or by the trapezoid rule,
        Eclipse SUMO's ballistic update (module docstring; recorded in ``params`` then).

    Returns
    -------
    PlatoonResult

    Raises
    ------
    StringStabError
        On invalid parameters or leaders.

    Examples
    --------
    >>> from stringstab.traffic import LinearController, sinusoid
    >>> res = simulate(sinusoid(omega=1.0, duration=20.0), LinearController(1.2, 0.5, 0.6), 3)
    >>> res.position.shape, bool(res.collided.any())
    ((4, 201), False)
    """
    leaders, batched = _stack_leaders(leader)
    if not all(callable(getattr(controller, m, None)) for m in ("command", "equilibrium_gap", "gains")):
        raise StringStabError(
            f"controller must be a stringstab Controller (command, equilibrium_gap, gains); "
            f"got {type(controller).__name__}"
        )
    N = count("n_followers", n_followers)
    P, T, dt = len(leaders), leaders[0].n_steps, leaders[0].dt
    plat = Platoon(P, N, dt=dt, tau=tau, delta=delta, model=model, limits=limits, length=length,
                   fractional_delay=fractional_delay, position_update=position_update)
    LX = np.ascontiguousarray(np.stack([tr.position for tr in leaders], axis=1))  # (T, P)
    LV = np.ascontiguousarray(np.stack([tr.speed for tr in leaders], axis=1))
    LA = np.ascontiguousarray(np.stack([tr.accel for tr in leaders], axis=1))
    v0 = LV[0][:, None] if initial_speed is None else np.asarray(initial_speed, dtype=np.float64)
    gap0 = controller.equilibrium_gap(v0 * np.ones((1, N))) if initial_gap is None else initial_gap
    plat.reset(LX[0], LV[0], LA[0], gap=gap0, speed=np.broadcast_to(v0, (P, N)), accel=0.0)

    if record:
        pos = np.empty((T, P, N + 1))
        spd = np.empty((T, P, N + 1))
        acc = np.empty((T, P, N + 1))
        cmd = np.empty((T, P, N))
    sumsq = np.zeros((P, N + 1))
    min_gap = np.full((P, N), np.inf)
    gains_rec: Array | None = None
    show_bar = (P * N * T > 1e8) if progress is None else bool(progress)
    steps: Any = range(T)
    if show_bar:
        from tqdm.auto import tqdm

        steps = tqdm(steps, total=T, unit="step", desc=f"simulate {P}x{N}", mininterval=0.5)
    for k in steps:
        obs = plat.observe(LX[k], LV[k], LA[k])
        u = controller.command(obs)
        if controller.time_varying:
            if record:
                K = controller.gains(obs)
                if K is not None:
                    if gains_rec is None:
                        gains_rec = np.empty((T, P, N, 3))
                    gains_rec[k] = np.broadcast_to(K, (P, N, 3))
        elif k == 0:
            K = controller.gains(obs)
            if K is not None:
                gains_rec = np.array(np.broadcast_to(K, (P, N, 3)))[None]
        np.minimum(min_gap, obs.gap, out=min_gap)
        if record:
            pos[k] = plat.position
            spd[k] = plat.speed
            acc[k] = plat.accel
        else:
            sumsq += plat.accel * plat.accel
        if k < T - 1:
            ul = plat.advance(u)
        else:
            lim = plat.limits
            ul = np.clip(u, lim.accel_min, lim.accel_max)
        if record:
            cmd[k] = ul
    if show_bar:
        steps.close()

    def lead(a: Array | None, axes: tuple[int, ...]) -> Array | None:
        if a is None:
            return None
        out = np.transpose(a, axes)
        return out if batched else out[0]

    if record:
        sumsq = np.einsum("tpn,tpn->pn", acc, acc)
    if gains_rec is not None:
        gains_out = lead(gains_rec, (1, 2, 0, 3))
    else:
        gains_out = None
    first_t = np.where(plat.first_collision_step >= 0, plat.first_collision_step * dt, np.nan)
    params: dict[str, Any] = {
        "dt": dt, "tau": np.asarray(plat.tau).tolist(), "delta": plat.delta, "model": model,
        "limits": vars(plat.limits).copy(), "length": plat.length,
        "headway": controller.headway, **controller.describe(),
        "leaders": [tr.name for tr in leaders] if batched else leaders[0].name,
    }
    if fractional_delay != "linear":
        params["fractional_delay"] = fractional_delay
    if position_update != "exact":
        params["position_update"] = position_update
    sq = (lambda a: a) if batched else (lambda a: a[0])
    return PlatoonResult(
        dt=dt,
        t=np.arange(T, dtype=np.float64) * dt,
        position=lead(pos, (1, 2, 0)) if record else None,
        speed=lead(spd, (1, 2, 0)) if record else None,
        accel=lead(acc, (1, 2, 0)) if record else None,
        command=lead(cmd, (1, 2, 0)) if record else None,
        gains=gains_out,
        collided=sq(plat.collided.copy()),
        collision_events=sq(plat.collision_events.copy()),
        first_collision_time=sq(first_t),
        min_gap=sq(min_gap),
        sum_sq_accel=sq(sumsq),
        params=params,
        length=plat.length,
    )
