"""A platoon whose vehicles move in Eclipse SUMO: :class:`SumoPlatoon` and :func:`cosimulate`.

:class:`SumoPlatoon` has the observe/advance contract of the toolkit's
:class:`~stringstab.traffic.Platoon` (one platoon, ``P = 1``), so every controller of
:mod:`stringstab.traffic.controllers` — fixed gains, a gain time series, a trained IDL policy,
CACC, IDM, any :class:`~stringstab.traffic.FunctionController` — runs unchanged:

``observe``
    reads every vehicle's position and speed from SUMO (a subscription per vehicle), writes
    them into a toolkit :class:`~stringstab.traffic.Platoon` that keeps what SUMO has no
    model of — each follower's first-order actuator lag state a_i (IDL eq 7) and the
    communication delay buffer of a_{i−1}(t − δ) (eq 4) — and returns that platoon's
    :class:`~stringstab.traffic.Observation` (gaps and speeds are SUMO's); the reaction
    delay θ_r (the command reaching the lag θ_r late) is that platoon's too, and the radio and
    the sensors (:class:`~stringstab.traffic.Onboard`) sit between it and the controller;
``advance``
    integrates the lag exactly over the step with the command held (the toolkit's zero-order
    hold, limits included), sends SUMO each follower's resulting speed v_{k+1} with
    ``vehicle.setSpeed`` (speed mode 0: SUMO's safe-speed rule, its acceleration bounds and
    speed limits off; lane change mode 0), sends the leader its prescribed next speed, and
    advances SUMO one step.

SUMO's ballistic update moves a vehicle by Δt (v_k + v_{k+1})/2 in a step; the toolkit's
simulator with ``position_update="trapezoid"`` does the same, so the two agree to round-off
(``stringstab sumo check``).  SUMO inserts the vehicles in its first step: toolkit step k is
SUMO time (k + 1)·Δt.  Positions are reported in the leader trajectory's coordinates (SUMO's lane
position plus a fixed offset).
"""

from __future__ import annotations

import tempfile
from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError, show
from ..params import DEFAULT_DELTA, DEFAULT_TAU, count
from ..progress import Progress
from ..traffic import Limits, Onboard, Platoon, PlatoonResult, Radio, SensorNoise, Trajectory
from ..traffic.controllers import Controller, Observation
from .runtime import SumoSession
from .scenario import LEADER_ID, follower_ids, straight_road

__all__ = ["DEFAULT_LENGTH", "SumoPlatoon", "ballistic_leader", "cosimulate", "vehicle_state"]

Array = npt.NDArray[np.float64]
#: Vehicle length, m (as the toolkit's simulator).
DEFAULT_LENGTH = 5.0


def vehicle_state(session: SumoSession, ids: list[str], t: float) -> tuple[Array, Array]:
    """Lane positions and speeds of ``ids`` from their subscriptions (after a step).

    Parameters
    ----------
    session : SumoSession
        The running SUMO, with position and speed subscribed for each of ``ids``.
    ids : list of str
        The vehicles, in the order of the result.
    t : float
        Simulation time (s), for the error message only.

    Returns
    -------
    x, v : ndarray
        Lane positions (m) and speeds (m/s), one per id.

    Raises
    ------
    StringStabError
        If a vehicle is no longer in the simulation (it arrived, collided out or was removed).
    """
    c = session.constants
    res = session.vehicle.getAllSubscriptionResults()
    x = np.empty(len(ids))
    v = np.empty(len(ids))
    for j, vid in enumerate(ids):
        r = res.get(vid)
        if not r:
            raise StringStabError(
                f"SUMO vehicle {vid!r} is no longer in the simulation at t = {t:.4g} s (it left "
                "the road or was removed); expected it to drive for the whole run")
        x[j] = r[c.VAR_LANEPOSITION]
        v[j] = r[c.VAR_SPEED]
    return x, v


def ballistic_leader(leader: Trajectory) -> tuple[Trajectory, float]:
    """The leader as SUMO moves it: its speed samples, positions by the trapezoid rule.

    SUMO is told the leader's speed every step and moves it by Δt (v_k + v_{k+1})/2 (the
    ballistic update); a trajectory whose positions are another integral of its speeds (the
    synthetic profiles' closed-form positions) is driven in SUMO as this one.  Accelerations are
    kept (they are what the followers receive over the delayed link).

    Parameters
    ----------
    leader : Trajectory
        The leader's profile (``dt`` s, positions m, speeds m/s, accelerations m/s²).

    Returns
    -------
    (Trajectory, float)
        The leader with trapezoidal positions, and the largest |position change| this made, m.

    Examples
    --------
    >>> from stringstab.traffic import from_speed
    >>> tr, moved = ballistic_leader(from_speed([0, 1, 2], [10.0, 11.0, 11.0], dt=1.0))
    >>> tr.position.tolist(), moved
    ([0.0, 10.5, 21.5], 0.0)
    """
    x = np.empty_like(leader.position)
    x[0] = leader.position[0]
    np.cumsum((leader.speed[1:] + leader.speed[:-1]) * (0.5 * leader.dt), out=x[1:])
    x[1:] += x[0]
    moved = float(np.max(np.abs(x - leader.position)))
    return Trajectory(leader.dt, x, leader.speed.copy(), leader.accel.copy(), leader.name), moved


class SumoPlatoon:
    """One platoon (a leader and N followers) moving in a running SUMO (see the module).

    Parameters
    ----------
    session : SumoSession
        The running SUMO, with the vehicles inserted (one step taken).
    leader : Trajectory
        The leader's prescribed motion; its speed is sent to SUMO every step.
    followers : list of str
        SUMO ids of the followers, first behind the leader first.
    leader_id : str
        SUMO id of the leader.
    tau, delta : float
        Actuator lag τ and communication delay δ, s (kept on the toolkit's side).
    limits : Limits, optional
        The toolkit's acceleration and speed bounds.
    length : float
        Vehicle length, m.
    fractional_delay : {"linear", "exact"}
        As in :class:`~stringstab.traffic.Platoon`.
    speed_mode : int
        SUMO speed mode of every vehicle; 0 (default) makes SUMO execute the commanded speed
        exactly.  Another value lets SUMO's safety rules override the controller (for tests).
    reaction_delay : float or array
        Reaction delay θ_r, s (kept on the toolkit's side like τ: the command reaches the lag
        θ_r late, :class:`~stringstab.traffic.Platoon`).

    Attributes
    ----------
    position, speed, accel : array (1, N + 1)
        The state of the current step (positions in the leader's coordinates).
    speed_override : float
        Largest |SUMO's speed − the commanded speed| seen so far, m/s (0 with speed mode 0).
    """

    def __init__(self, session: SumoSession, leader: Trajectory, followers: list[str], *,
                 leader_id: str = LEADER_ID, tau: npt.ArrayLike = DEFAULT_TAU,
                 delta: float = DEFAULT_DELTA, limits: Limits | None = None,
                 length: float = DEFAULT_LENGTH, fractional_delay: Any = "linear",
                 speed_mode: int = 0, reaction_delay: npt.ArrayLike = 0.0) -> None:
        self.session, self.leader, self.leader_id = session, leader, leader_id
        self.ids = [leader_id, *followers]
        self.N = len(followers)
        self.dt = float(leader.dt)
        if abs(self.dt - session.dt) > 1e-9 * max(1.0, self.dt):
            raise StringStabError(
                f"the leader's step is {self.dt:g} s but SUMO runs with {session.dt:g} s; "
                "expected one step")
        self.inner = Platoon(1, self.N, dt=self.dt, tau=tau, delta=delta, model="lag",
                             limits=limits, length=length, fractional_delay=fractional_delay,
                             position_update="trapezoid", reaction_delay=reaction_delay)
        self.speed_override = 0.0
        self._vcmd: Array | None = None
        present = set(session.vehicle.getIDList())
        missing = [v for v in self.ids if v not in present]
        if missing:
            raise StringStabError(
                f"SUMO vehicle(s) {', '.join(missing)} not in the simulation at "
                f"t = {session.simulation.getTime():g} s; expected {', '.join(self.ids)}")
        c = session.constants
        for vid in self.ids:
            session.vehicle.setSpeedMode(vid, int(speed_mode))
            session.vehicle.setLaneChangeMode(vid, 0)
            session.vehicle.subscribe(vid, [c.VAR_LANEPOSITION, c.VAR_SPEED])
        x, _ = self._read()
        self.offset = float(leader.position[0]) - float(x[0])

    @property
    def position(self) -> Array:
        """Positions of the current step, m, shape (1, N + 1), in the leader's coordinates."""
        return self.inner.position

    @property
    def speed(self) -> Array:
        """Speeds of the current step, m/s, shape (1, N + 1); column 0 is the leader."""
        return self.inner.speed

    @property
    def accel(self) -> Array:
        """Accelerations of the current step, m/s², shape (1, N + 1); column 0 is the leader."""
        return self.inner.accel

    @property
    def step(self) -> int:
        """Steps taken by the toolkit's side of the platoon (its inner :class:`Platoon`)."""
        return self.inner.step

    @property
    def limits(self) -> Limits:
        """The toolkit's acceleration and speed bounds."""
        return self.inner.limits

    def _read(self) -> tuple[Array, Array]:
        return vehicle_state(self.session, self.ids, self.session.simulation.getTime())

    def reset(self, accel: npt.ArrayLike = 0.0) -> None:
        """Take the followers' gaps and speeds from SUMO; set their accelerations to ``accel``.

        The delay history is set to ``accel`` too.
        """
        x, v = self._read()
        x = x + self.offset
        gaps = x[:-1] - x[1:] - self.inner.length
        tr = self.leader
        self.inner.reset(x[:1], v[:1], tr.accel[:1], gap=gaps[None], speed=v[None, 1:], accel=accel)
        self._vcmd = v.copy()

    def observe(self, leader_position: npt.ArrayLike | None = None,
                leader_speed: npt.ArrayLike | None = None,
                leader_accel: npt.ArrayLike | None = None) -> Observation:
        """The followers' observation at the current step, from SUMO's positions and speeds.

        The leader's position and speed are SUMO's (arguments given are not used for them);
        its acceleration is ``leader_accel`` (default: the trajectory's at this step), since
        SUMO's ``getAcceleration`` is a finite difference of speeds.
        """
        x, v = self._read()
        if self._vcmd is not None:
            self.speed_override = max(self.speed_override, float(np.max(np.abs(v - self._vcmd))))
        k = min(self.inner.step, self.leader.n_steps - 1)
        a_l = self.leader.accel[k] if leader_accel is None else leader_accel
        self.inner.position[0, 1:] = x[1:] + self.offset
        self.inner.speed[0, 1:] = v[1:]
        return self.inner.observe(x[:1] + self.offset, v[:1], np.atleast_1d(a_l))

    def advance(self, command: npt.ArrayLike) -> Array:
        """Hold u over the step (exact lag), command SUMO's speeds, step SUMO; returns u limited."""
        u = self.inner.advance(command)
        k = self.inner.step  # the step being entered
        tr = self.leader
        v_next = np.empty(self.N + 1)
        v_next[0] = tr.speed[min(k, tr.n_steps - 1)]
        v_next[1:] = self.inner.speed[0, 1:]
        veh = self.session.vehicle
        for vid, vk in zip(self.ids, v_next):
            veh.setSpeed(vid, float(vk))
        self._vcmd = v_next
        self.session.step()
        return u


def cosimulate(leader: Trajectory, controller: Controller, n_followers: int, *,
               tau: float = DEFAULT_TAU, delta: float = DEFAULT_DELTA, api: str = "libsumo",
               limits: Limits | None = None, length: float = DEFAULT_LENGTH,
               initial_gap: npt.ArrayLike | None = None,
               initial_speed: npt.ArrayLike | None = None,
               fractional_delay: Any = "linear", speed_mode: int = 0,
               progress: bool = False, on_step: Any = None, reaction_delay: float = 0.0,
               radio: Radio | None = None, sensors: SensorNoise | None = None) -> PlatoonResult:
    """Run ``n_followers`` behind ``leader`` in Eclipse SUMO on a straight generated road.

    The same inputs and result as :func:`stringstab.traffic.simulate` (one leader), so
    metrics, M_fss, figures and output files work as they are; the vehicles' motion is SUMO's
    (see the module).

    Parameters
    ----------
    leader : Trajectory
        The leader; its ``dt`` is SUMO's step.
    controller : Controller
        Any toolkit controller.
    n_followers : int
        Followers N.
    tau, delta : float
        Actuator lag and communication delay, s.
    api : {"libsumo", "traci"}
        How to run SUMO.
    limits, length, initial_gap, initial_speed, fractional_delay
        As for :func:`~stringstab.traffic.simulate`.
    speed_mode : int
        SUMO speed mode (0: SUMO executes the commanded speeds).
    progress : bool
        Show progress (a bar on a terminal, lines otherwise).
    on_step : callable, optional
        Called as ``on_step(k, session)`` after each step (tests use it to break SUMO).
    reaction_delay : float
        Reaction delay θ_r, s, kept on the toolkit's side like τ (the command reaches the lag
        θ_r late; SUMO gets the resulting speeds).
    radio, sensors : Radio, SensorNoise, optional
        The followers' V2V radio and sensors, on the toolkit's side
        (:class:`~stringstab.traffic.Onboard`); as for :func:`~stringstab.traffic.simulate`.

    Returns
    -------
    PlatoonResult
        With ``params["simulator"] = "sumo"``, the API, SUMO's version and the largest speed
        override (``sumo_speed_override``, m/s); θ_r, the radio and the sensors in ``params``
        when given, what the radio did in ``radio``.

    Raises
    ------
    StringStabError
        Bad inputs, SUMO missing, failing to start or stopping mid-run (nothing is returned).
    """
    N = count("n_followers", n_followers)
    if not all(callable(getattr(controller, m, None)) for m in ("command", "equilibrium_gap", "gains")):
        raise StringStabError(
            f"controller must be a stringstab Controller (command, equilibrium_gap, gains); "
            f"got {type(controller).__name__}")
    T, dt = leader.n_steps, float(leader.dt)
    v0 = float(leader.speed[0]) if initial_speed is None else initial_speed
    v0a = np.broadcast_to(np.asarray(v0, dtype=np.float64), (N,)).copy()
    gap0 = (controller.equilibrium_gap(v0a * np.ones((1, N))) if initial_gap is None
            else initial_gap)
    gap0 = np.broadcast_to(np.asarray(gap0, dtype=np.float64), (1, N)).ravel()
    if not (np.isfinite(gap0).all() and np.isfinite(v0a).all()):
        raise StringStabError(f"initial gaps and speeds must be finite; got {show(gap0)}, {show(v0a)}")
    onboard = None
    if radio is not None or sensors is not None:
        onboard = Onboard(controller, (1, N), dt, radio=radio, sensors=sensors)
    distance = float(leader.position[-1] - leader.position[0])
    with tempfile.TemporaryDirectory(prefix="stringstab-sumo-") as tmp:
        road = straight_road(tmp, distance=distance, gaps=gap0, speeds=v0a,
                             leader_speed=float(leader.speed[0]), length=length)
        with SumoSession(road.sumo_args(), dt=dt, api=api) as session:
            session.step()  # insertion: SUMO time dt is toolkit step 0
            plat = SumoPlatoon(session, leader, follower_ids(N), tau=tau, delta=delta,
                               limits=limits, length=length, fractional_delay=fractional_delay,
                               speed_mode=speed_mode, reaction_delay=reaction_delay)
            plat.reset(accel=0.0)
            version = _version(session)
            result = run_loop(plat, controller if onboard is None else onboard, T,
                              progress=progress, on_step=on_step, desc=f"sumo {N} followers")
    result.params.update({
        "tau": np.asarray(tau).tolist(), "delta": float(delta), "model": "lag",
        "limits": vars(plat.limits).copy(), "length": float(length),
        "headway": controller.headway, **controller.describe(), "leaders": leader.name,
        "simulator": "sumo", "sumo_api": api, "sumo_version": version,
        "position_update": "ballistic (SUMO)",
        "sumo_speed_override": plat.speed_override,
    })
    if fractional_delay != "linear":
        result.params["fractional_delay"] = fractional_delay
    if plat.inner.reaction_delay.any():
        result.params["reaction_delay"] = plat.inner.reaction_delay.tolist()
    if radio is not None:
        result.params["radio"] = radio.describe()
    if sensors is not None:
        result.params["sensors"] = sensors.describe()
    rec = None if onboard is None else onboard.summary()
    if rec is not None:
        result.radio = {k: v[0] for k, v in rec.items()}
    return result


def _version(session: SumoSession) -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("eclipse-sumo")
    except PackageNotFoundError:  # pragma: no cover - SUMO from elsewhere
        return ""


def run_loop(plat: Any, controller: Controller, T: int, *, progress: bool = False,
             on_step: Any = None, desc: str = "sumo") -> PlatoonResult:
    """Step a platoon with the observe/advance contract ``T`` times, recording as it goes.

    Records like :func:`~stringstab.traffic.simulate` (``record=True``); the result has no
    ``params`` beyond ``dt``.

    Parameters
    ----------
    plat : platoon
        The SUMO-backed platoon of this module (its ``N``, ``dt`` in s, ``observe()``,
        ``advance(u)``, state arrays, ``limits``, ``inner`` and ``session`` are used).
    controller : Controller
        Maps each observation to the followers' commanded accelerations (m/s²).
    T : int
        Number of recorded samples (SUMO is advanced T − 1 times; the last command is only
        clipped and recorded).
    progress : bool, default False
        Show a progress bar (or periodic lines when not on a terminal).
    on_step : callable, optional
        Called as ``on_step(k, plat.session)`` after each step.
    desc : str, default "sumo"
        Label of the progress bar.

    Returns
    -------
    PlatoonResult
        Positions, speeds, accelerations, commands and smallest gaps over the ``T`` steps.
    """
    N, dt = plat.N, plat.dt
    pos = np.empty((T, N + 1))
    spd = np.empty((T, N + 1))
    acc = np.empty((T, N + 1))
    cmd = np.empty((T, N))
    min_gap = np.full((1, N), np.inf)
    gains_rec: Array | None = None
    bar = Progress(T, desc, unit="step", enabled=progress)
    try:
        for k in range(T):
            obs = plat.observe()
            u = controller.command(obs)
            if controller.time_varying:
                K = controller.gains(obs)
                if K is not None:
                    if gains_rec is None:
                        gains_rec = np.empty((T, N, 3))
                    gains_rec[k] = np.broadcast_to(K, (1, N, 3))[0]
            elif k == 0:
                K = controller.gains(obs)
                if K is not None:
                    gains_rec = np.array(np.broadcast_to(K, (1, N, 3)))
            np.minimum(min_gap, obs.gap, out=min_gap)
            pos[k] = plat.position[0]
            spd[k] = plat.speed[0]
            acc[k] = plat.accel[0]
            if k < T - 1:
                ul = plat.advance(u)
                if on_step is not None:
                    on_step(k, plat.session)
            else:
                lim = plat.limits
                ul = np.clip(u, lim.accel_min, lim.accel_max)
            cmd[k] = np.broadcast_to(ul, (1, N))[0]
            bar.update()
    finally:
        bar.close()
    inner = plat.inner
    first_t = np.where(inner.first_collision_step >= 0, inner.first_collision_step * dt, np.nan)[0]
    gains_out = None
    if gains_rec is not None:
        gains_out = np.transpose(gains_rec, (1, 0, 2))  # (N, T or 1, 3)
    return PlatoonResult(
        dt=dt, t=np.arange(T, dtype=np.float64) * dt,
        position=pos.T.copy(), speed=spd.T.copy(), accel=acc.T.copy(), command=cmd.T.copy(),
        gains=gains_out, collided=inner.collided[0].copy(),
        collision_events=inner.collision_events[0].copy(), first_collision_time=first_t,
        min_gap=min_gap[0], sum_sq_accel=np.einsum("tn,tn->n", acc, acc),
        params={"dt": dt}, length=inner.length)
