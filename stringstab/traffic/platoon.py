"""Whole platoon runs: :func:`simulate`, N followers behind prescribed leaders, many platoons at once.

:func:`simulate` steps a :class:`~stringstab.traffic.dynamics.Platoon` (the IDL paper's
third-order model, eqs 5-7, or the kinematic one, eqs 1-2; discretisation, delay, limits and
collisions are described in :mod:`stringstab.traffic.dynamics`) with a controller
(:mod:`~stringstab.traffic.controllers`) behind each leader and returns a
:class:`~stringstab.traffic.result.PlatoonResult`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError
from ..params import DEFAULT_DELTA, DEFAULT_TAU, count
from .controllers.base import Controller
from .dynamics import FractionalDelay, Model, Platoon, PositionUpdate
from .limits import DEFAULT_LENGTH, Limits
from .onboard import Onboard
from .radio import Radio
from .result import PlatoonResult
from .sensors import SensorNoise
from .trajectory import Trajectory

__all__ = ["simulate"]

Array = npt.NDArray[np.float64]


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
    progress: bool | Callable[[int], None] | None = None,
    fractional_delay: FractionalDelay = "linear",
    position_update: PositionUpdate = "exact",
    reaction_delay: npt.ArrayLike = 0.0,
    radio: Radio | None = None,
    sensors: SensorNoise | None = None,
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
        See :mod:`stringstab.traffic.dynamics`.
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
        Show progress (:class:`stringstab.progress.Progress`: a bar on a terminal, plain lines
        otherwise); by default only for long runs (over 10⁸ vehicle-steps).  A callable is
        called with 1 at each step instead (the caller reports).
    fractional_delay : {"linear", "exact"}
        A delay that is not a multiple of Δt: interpolated linearly between received samples
        (default), or the predecessor's exact acceleration inside the step, the loop the
        sampled-data certificate certifies (module docstring; recorded in ``params`` then).
    position_update : {"exact", "trapezoid"}
        Positions by the exact integral of the lag model (default) or by the trapezoid rule,
        Eclipse SUMO's ballistic update (module docstring; recorded in ``params`` then).
    reaction_delay : float or array
        Reaction delay θ_r, s (≥ 0, issue 25): every follower applies its command θ_r late,
        τ ȧ = u(t − θ_r) − a, integrated exactly for any θ_r (:mod:`stringstab.traffic.dynamics`);
        an array of shape (N,) or (P, N) gives each vehicle its own.  The commands before
        t = 0 are the equilibrium command.  ``command`` records u as computed (applied θ_r
        later).  Recorded in ``params`` when > 0; 0 (default) changes nothing, bit for bit.
    radio : Radio, optional
        The V2V link of every follower (:mod:`stringstab.traffic.radio`, issue 26): messages
        every N steps, held, lost at random, a fallback to ACC when stale.  None (default): the
        acceleration arrives every step, as without radio.  Recorded in ``params["radio"]``;
        what it did per follower in the result's ``radio``.  With a ``stale_after`` the gains
        in force are recorded at every step (the fallback's where stale).
    sensors : SensorNoise, optional
        Noise and a filter on the measured gap, gap rate and own speed
        (:mod:`stringstab.traffic.sensors`); the trajectories, collisions and minimum gaps stay
        the true ones.  Recorded in ``params["sensors"]``.

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
                   fractional_delay=fractional_delay, position_update=position_update,
                   reaction_delay=reaction_delay)
    LX = np.ascontiguousarray(np.stack([tr.position for tr in leaders], axis=1))  # (T, P)
    LV = np.ascontiguousarray(np.stack([tr.speed for tr in leaders], axis=1))
    LA = np.ascontiguousarray(np.stack([tr.accel for tr in leaders], axis=1))
    v0 = LV[0][:, None] if initial_speed is None else np.asarray(initial_speed, dtype=np.float64)
    gap0 = controller.equilibrium_gap(v0 * np.ones((1, N))) if initial_gap is None else initial_gap
    plat.reset(LX[0], LV[0], LA[0], gap=gap0, speed=np.broadcast_to(v0, (P, N)), accel=0.0)
    onboard = None
    if radio is not None or sensors is not None:
        onboard = Onboard(controller, (P, N), dt, radio=radio, sensors=sensors)
        controller = onboard

    if record:
        pos = np.empty((T, P, N + 1))
        spd = np.empty((T, P, N + 1))
        acc = np.empty((T, P, N + 1))
        cmd = np.empty((T, P, N))
    sumsq = np.zeros((P, N + 1))
    min_gap = np.full((P, N), np.inf)
    gains_rec: Array | None = None
    from ..progress import Progress  # a bar on a terminal, plain lines otherwise

    show_bar = (P * N * T > 1e8) if progress is None else progress is True
    meter = Progress(T, f"simulate {P}x{N}", unit="steps", enabled=show_bar)
    each_step = progress if callable(progress) else meter.update  # the caller's own count
    for k in range(T):
        each_step(1)
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
    meter.close()

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
    if plat.reaction_delay.any():
        params["reaction_delay"] = plat.reaction_delay.tolist()
    if radio is not None:
        params["radio"] = radio.describe()
    if sensors is not None:
        params["sensors"] = sensors.describe()
    radio_rec = None if onboard is None else onboard.summary()
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
        radio=None if radio_rec is None else {k: sq(v) for k, v in radio_rec.items()},
    )
