"""Platoon dynamics: the stepping core :class:`Platoon`, many platoons of N followers at once.

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
from typing import Any, Literal

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError, show
from ..params import DEFAULT_DELTA, DEFAULT_TAU
from .controllers.base import Observation
from .limits import DEFAULT_LENGTH, Limits

__all__ = ["FractionalDelay", "Model", "Platoon", "PositionUpdate"]

Array = npt.NDArray[np.float64]

#: Vehicle update: the third-order model with exact ZOH (eqs 5-7) or the kinematic one (eqs 1-2).
Model = Literal["lag", "kinematic"]
#: How a delay that is not a multiple of Δt is received.
FractionalDelay = Literal["linear", "exact"]
#: How positions advance with ``model="lag"``.
PositionUpdate = Literal["exact", "trapezoid"]


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

    Use :func:`~stringstab.traffic.platoon.simulate` for whole runs; this class is the building
    block of the simulator and of the Gymnasium environments (:mod:`stringstab.traffic.env`).  A step is
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

    #: The arrays that hold the platoon's state between two steps (with :attr:`step`).
    STATE_ARRAYS: tuple[str, ...] = ("position", "speed", "accel", "_buf", "_ubuf", "collided",
                                     "collision_events", "first_collision_step", "_in_collision")

    def state(self) -> tuple[dict[str, Any], dict[str, Array]]:
        """The platoon's state between two steps, to continue bit for bit (a checkpoint).

        Returns
        -------
        meta : dict
            ``step`` and ``any_in_collision`` (JSON-ready).
        arrays : dict of str to ndarray
            Copies of the arrays named in :attr:`STATE_ARRAYS` (positions, speeds,
            accelerations, the delay buffers and the collision records).
        """
        meta = {"step": int(self.step), "any_in_collision": bool(self._any_in_collision)}
        return meta, {a: np.array(getattr(self, a), copy=True) for a in self.STATE_ARRAYS}

    def load_state(self, meta: dict[str, Any], arrays: dict[str, Any]) -> None:
        """Restore :meth:`state` output into this platoon (same shape; checked).

        Parameters
        ----------
        meta : dict
            ``step`` and ``any_in_collision``, as :meth:`state` returns them.
        arrays : dict of str to array_like
            The arrays of :meth:`state`, by name.

        Raises
        ------
        StringStabError
            If a key or an array is missing, or an array has another shape.
        """
        missing = [k for k in ("step", "any_in_collision") if k not in meta]
        missing += [a for a in self.STATE_ARRAYS if a not in arrays]
        if missing:
            raise StringStabError(f"platoon state: expected {', '.join(missing)}; found "
                                  f"{sorted(meta)} and arrays {sorted(arrays)}")
        for a in self.STATE_ARRAYS:
            dst, src = getattr(self, a), np.asarray(arrays[a])
            if src.shape != dst.shape:
                raise StringStabError(f"platoon state {a}: expected shape {dst.shape}; "
                                      f"found {src.shape}")
            dst[...] = src
        self.step = int(meta["step"])
        self._any_in_collision = bool(meta["any_in_collision"])

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
