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

Reaction delay θ_r (``reaction_delay``, issue 25)
    The command is applied θ_r late: τ ȧ_i = u_i(t − θ_r) − a_i, u_i the held (ZOH) command
    signal.  With θ_r = q Δt + f (q integer, 0 ≤ f < Δt) the command applied over step k is
    u_{k−q−1} for the first f seconds and u_{k−q} for the remaining Δt − f: the lag is
    integrated exactly over both constant pieces (the closed form above, once with h = f and
    once with h = Δt − f, from the state the first piece ends in), the speed and position
    integrals too; with ``model="kinematic"`` the acceleration is the applied command itself and
    speed and position are the exact integrals of the two pieces.  θ_r may differ per vehicle
    (an array broadcasting to ``(P, N)``).  The commands before t = 0 are the initial
    acceleration (0 in an equilibrium start: the equilibrium command), a constant history as
    for the delay δ.  With θ_r = 0 for every vehicle the step is the one above, bit for bit.
    With ``fractional_delay="exact"`` the predecessor's acceleration inside the step is
    evaluated on the same two pieces.

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
from ..params import DEFAULT_DELTA, DEFAULT_TAU, check_reaction_delay
from .controllers.base import Observation
from .limits import DEFAULT_LENGTH, Limits

__all__ = ["FractionalDelay", "Model", "Platoon", "PositionUpdate", "lag_pieces"]

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


def _check_reaction(reaction_delay: npt.ArrayLike, shape: tuple[int, int]) -> Array:
    """θ_r per follower, (P, N): each finite, ≥ 0 and ≤ 100 s (:func:`check_reaction_delay`)."""
    try:
        r = np.asarray(reaction_delay, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise StringStabError(f"reaction_delay (reaction delay θ_r) must be a number >= 0 s; "
                              f"got {show(reaction_delay)}") from e
    for v in np.unique(r.ravel()):
        check_reaction_delay(v)
    try:
        return np.broadcast_to(r, shape)
    except ValueError as e:
        raise StringStabError(f"reaction_delay must broadcast to (n_platoons, n_followers)={shape}; "
                              f"got shape {r.shape}") from e


def lag_pieces(h: Array, tau: Array) -> tuple[Array, Array, Array]:
    """The exact ZOH constants of the lag over a piece of h seconds: e, τ(1 − e), τ(h − τ(1 − e)).

    Over h seconds of a constant command u, τ ȧ = u − a (IDL eq 7) gives, with ā = a_0 − u,
    a(h) = u + ā e, v(h) = v_0 + u h + ā τ(1 − e), x(h) = x_0 + v_0 h + u h²/2 + ā τ(h − τ(1 − e)),
    e = exp(−h/τ).

    Parameters
    ----------
    h : array
        Piece durations, s (≥ 0; 0 gives e = 1 and zero integrals).
    tau : array
        Actuator lags τ, s (> 0), broadcasting with ``h``.

    Returns
    -------
    (e, c1, c2) : arrays
        exp(−h/τ), τ(1 − e) and τ(h − τ(1 − e)).

    Examples
    --------
    >>> e, c1, c2 = lag_pieces(np.array([0.0, 0.1]), np.array([0.1, 0.1]))
    >>> e.round(6).tolist(), c1.round(6).tolist(), c2.round(6).tolist()
    ([1.0, 0.367879], [0.0, 0.063212], [0.0, 0.003679])
    """
    e = np.exp(-h / tau)
    c1 = tau * (1.0 - e)
    return e, c1, tau * (h - c1)


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
    reaction_delay : float or array
        Reaction delay θ_r, s (≥ 0): the command is applied θ_r late (the module docstring);
        an array broadcasts against ``(P, N)``.  0 (default) is the step without it, bit for bit.

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
                 position_update: PositionUpdate = "exact",
                 reaction_delay: npt.ArrayLike = 0.0) -> None:
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
        self.state_arrays = self.STATE_ARRAYS
        self._setup_reaction(reaction_delay, tau_b)

    def _setup_reaction(self, reaction_delay: npt.ArrayLike, tau_b: Array) -> None:
        """θ_r = q Δt + f per follower: the command history and the constants of both pieces."""
        P, N, dt = self.P, self.N, self.dt
        theta = _check_reaction(reaction_delay, (P, N))
        self.reaction_delay = np.asarray(reaction_delay, dtype=np.float64)
        self._react = bool((theta > 0).any())
        if not self._react:
            return
        q = np.floor(theta / dt + 1e-9)
        f = theta - q * dt
        f = np.where(f < 1e-9 * dt, 0.0, f)
        qi = q.astype(np.int64)
        self._cring = int(qi.max()) + 2
        self._cbuf = np.zeros((self._cring, P, N))  # the commands computed, newest at k % ring
        self._rq: int | npt.NDArray[np.int64] = int(qi[0, 0]) if (qi == qi[0, 0]).all() else qi
        self._one_piece = not (f > 0).any() and not self._exact_frac
        self._h1 = f  # the first piece (the older command u_{k−q−1}), then Δt − f of u_{k−q}
        self._p1 = lag_pieces(f, tau_b)
        self._p2 = lag_pieces(dt - f, tau_b)
        extra: tuple[str, ...] = ("_cbuf",)
        if self._exact_frac:
            # the exact fractional delay reads each vehicle's acceleration at (1 − f_δ)Δt into
            # its step, evaluated on the two pieces in advance() and kept here per step
            s = (1.0 - self._frac) * dt
            self._mid_first = s <= f
            self._mid_e = np.exp(-np.where(self._mid_first, s, s - f) / tau_b)
            self._mbuf = np.zeros((self._ring, P, N + 1))
            extra += ("_mbuf",)
        self.state_arrays = self.STATE_ARRAYS + extra

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
        if self._react:  # the commands before t = 0: the initial acceleration (a = u)
            self._cbuf[:, r] = A[:, 1:]
            if self._exact_frac:
                self._mbuf[:, r] = A
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
            if self._exact_frac and self._react:
                ad = self._mbuf[(k - self._n_delay - 1) % self._ring][:, :-1].copy()
                ad[:, 0] = lead  # the leader's acceleration between samples is not modelled
            elif self._exact_frac:
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
            accelerations, the delay buffers and the collision records), and with a reaction
            delay θ_r > 0 its command history (``state_arrays`` names them all).
        """
        meta = {"step": int(self.step), "any_in_collision": bool(self._any_in_collision)}
        return meta, {a: np.array(getattr(self, a), copy=True) for a in self.state_arrays}

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
        missing += [a for a in self.state_arrays if a not in arrays]
        if missing:
            raise StringStabError(f"platoon state: expected {', '.join(missing)}; found "
                                  f"{sorted(meta)} and arrays {sorted(arrays)}")
        for a in self.state_arrays:
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
        if self._react:
            xn, vn, an = self._advance_delayed(u, xo, vo, ao)
        else:
            xn, vn, an = self._held_step(u, xo, vo, ao)
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

    def _held_step(self, u: Array, xo: Array, vo: Array, ao: Array) -> tuple[Array, Array, Array]:
        """One step with u held over all of it: the exact ZOH of the lag, or eqs 1-2."""
        dt = self.dt
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
        return xn, vn, an

    def _advance_delayed(self, u: Array, xo: Array, vo: Array, ao: Array) -> tuple[Array, Array, Array]:
        """One step with the command applied θ_r late: two constant pieces (module docstring)."""
        k, R, q = self.step, self._cring, self._rq
        self._cbuf[k % R] = u
        if isinstance(q, int):
            u2, u1 = self._cbuf[(k - q) % R], self._cbuf[(k - q - 1) % R]
        else:
            u2 = np.take_along_axis(self._cbuf, ((k - q) % R)[None], axis=0)[0]
            u1 = np.take_along_axis(self._cbuf, ((k - q - 1) % R)[None], axis=0)[0]
        if self._one_piece:  # θ_r a whole number of steps: the command of step k − q, held
            return self._held_step(np.array(u2, copy=True), xo, vo, ao)
        h1 = self._h1
        h2 = self.dt - h1
        if self.model == "lag":
            (e1, c11, c21), (e2, c12, c22) = self._p1, self._p2
            d1 = ao - u1
            a1 = u1 + d1 * e1
            v1 = vo + u1 * h1 + d1 * c11
            x1 = xo + vo * h1 + u1 * (0.5 * h1 * h1) + d1 * c21
            d2 = a1 - u2
            an = u2 + d2 * e2
            vn = v1 + u2 * h2 + d2 * c12
            xn = x1 + v1 * h2 + u2 * (0.5 * h2 * h2) + d2 * c22
            if self.position_update == "trapezoid":
                xn = xo + 0.5 * self.dt * (vo + vn)
            mid = (np.where(self._mid_first, u1 + d1 * self._mid_e, u2 + d2 * self._mid_e)
                   if self._exact_frac else None)
        else:
            an = np.array(u2, copy=True)
            v1 = vo + u1 * h1
            vn = v1 + u2 * h2
            xn = xo + vo * h1 + u1 * (0.5 * h1 * h1) + v1 * h2 + u2 * (0.5 * h2 * h2)
            mid = np.where(self._mid_first, u1, u2) if self._exact_frac else None
        if mid is not None:
            self._mbuf[k % self._ring][:, 1:] = mid
        return xn, vn, an
