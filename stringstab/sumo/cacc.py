"""SUMO's own CACC car-following model: its modes as linear laws, certified one by one.

The law (SUMO 1.28, ``MSCFModel_CACC``, Milanés & Shladover 2014 / Xiao, Wang & van Arem
2017), when the predecessor is also a CACC vehicle and the time gap is below 1.5 s, sets the
next speed from the spacing error e = s − s_0 − T v (s the bumper-to-bumper gap, s_0 the
vType's ``minGap``, T its ``tau``) and its rate ė = Δv − T a (a the vehicle's own acceleration
over the last step, SUMO's ``getAcceleration``):

    v_{k+1} = v_k + g_s e_k + g_d ė_k,   (g_s, g_d) per mode:
    gap control (0 < e < 0.2 m)        gapControlGainGap, gapControlGainGapDot (0.45, 0.0125)
    collision avoidance (e < 0)        collisionAvoidanceGainGap, ...GapDot    (0.45, 0.05)
    gap closing (otherwise)            gapClosingControlGainGap, ...GapDot     (0.005, 0.05)

The gains are per step and tuned for 0.1 s: SUMO divides the speed change by
h = max(Δt, 0.1 s), so the acceleration is u = k_p e + k_d ė with k_p = g_s/h, k_d = g_d/h.
This form was checked against SUMO 1.28 itself (:func:`law_residual` reproduces its speeds
to round-off in every step of every mode; the sign of T a is a minus, as the derivative of e).

With no actuator lag (SUMO's CACC vehicles have none: a = u), ė = Δv − T u, and solving for u
gives each mode in the toolkit's linear form (IDL eq 4):

    u = k_x (s − T v − s_0) + k_v Δv,   k_x = k_p/(1 + k_d T),   k_v = k_d/(1 + k_d T),
    k_a = 0 (SUMO's CACC uses the predecessor's speed, not its acceleration), T* = T, l_0 = s_0.

Each mode is certified with the toolkit's certificate — continuous time and sampled at the step
— with τ = 1 ms standing in for "no lag" (the certificate needs τ > 0) and δ = 0.  Without lag,
Γ(s) = (k_v s + k_x)/(s² + (k_v + k_x T) s + k_x), whose |Γ(jω)| ≤ 1 for all ω iff
k_x T² + 2 k_v T ≥ 2 (with k_x, k_v + k_x T > 0): the closed form is reported beside the
certificate as an independent check.  SUMO's discrete law is also swept exactly
(:func:`discrete_sweep`): a kinematic vehicle moved ballistically, u_k = k_p e_k + k_d (Δv_k −
T u_{k−1}).  None of this certifies the *switching* between modes, nor SUMO's safe-speed
override, its acceleration bounds or its speed-control mode (time gap > 2 s); the platoon run
(:func:`measure_platoon`) measures what the switched law does.
"""

from __future__ import annotations

import math
import tempfile
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError, show
from ..traffic import Trajectory
from .runtime import SumoSession, read_xml
from .scenario import LEADER_ID, follower_ids, straight_road

__all__ = ["DEFAULTS", "MODES", "NO_LAG_TAU", "CACCType", "ModeLaw", "certify_modes",
           "discrete_sweep", "law_residual", "measure_platoon", "mode_laws", "read_vtype"]

Array = npt.NDArray[np.float64]

#: SUMO's defaults of the CACC parameters (MSCFModel_CACC.cpp) and of tau and minGap.
DEFAULTS: dict[str, float] = {
    "speedControlGainCACC": -0.4, "gapClosingControlGainGap": 0.005,
    "gapClosingControlGainGapDot": 0.05, "gapControlGainGap": 0.45,
    "gapControlGainGapDot": 0.0125, "collisionAvoidanceGainGap": 0.45,
    "collisionAvoidanceGainGapDot": 0.05, "tau": 1.0, "minGap": 2.5, "length": 5.0,
}
#: The modes of the gap-control law: SUMO's name and its (spacing, rate) gain parameters.
MODES: dict[str, tuple[str, str, str]] = {
    "gap control": ("CACC_GAP", "gapControlGainGap", "gapControlGainGapDot"),
    "gap closing": ("CACC_GAP_CL", "gapClosingControlGainGap", "gapClosingControlGainGapDot"),
    "collision avoidance": ("CACC_CA", "collisionAvoidanceGainGap", "collisionAvoidanceGainGapDot"),
}
#: The actuator lag standing in for SUMO's none in the toolkit's certificate, s.
NO_LAG_TAU = 1e-3
#: The step SUMO's CACC gains are tuned for, s.
TUNED_STEP = 0.1


@dataclass(frozen=True)
class CACCType:
    """A vType of SUMO's CACC model: where it came from and its parameters.

    SUMO's defaults are filled in for the parameters not given.
    """

    id: str
    source: str
    params: dict[str, float]
    xml: str = field(repr=False)

    @property
    def headway(self) -> float:
        """T, the vType's ``tau``, s."""
        return self.params["tau"]

    @property
    def min_gap(self) -> float:
        """s_0, the vType's ``minGap``, m."""
        return self.params["minGap"]

    @property
    def length(self) -> float:
        """Vehicle length, m."""
        return self.params["length"]


def read_vtype(spec: str) -> CACCType:
    """The vType ``FILE:TYPE`` of a route or additional file, which must use the CACC model.

    The model is named by ``carFollowModel="CACC"`` or a ``<carFollowing-CACC .../>`` child
    (whose attributes then count too).

    Parameters
    ----------
    spec : str
        ``FILE:TYPE``: a SUMO route or additional file (XML) and the id of a vType in it.

    Returns
    -------
    CACCType
        The vType's id, file, CACC parameters (SUMO's defaults where absent; tau = T* in s,
        minGap in m, length in m) and its XML element.

    Raises
    ------
    StringStabError
        A spec without ``:TYPE``, a missing or malformed file, no such vType, another model,
        or a parameter that is not a finite number.
    """
    if ":" not in str(spec):
        raise StringStabError(f"--vtype must be FILE.rou.xml:TYPE; got {show(spec)}")
    fname, tid = str(spec).rsplit(":", 1)
    root = read_xml(fname, "--vtype", "a route file", "a SUMO route file (XML)")
    found = [el for el in root.iter("vType") if el.get("id") == tid]
    if not found:
        ids = [el.get("id") for el in root.iter("vType")]
        raise StringStabError(f"--vtype {fname}: no vType {tid!r}; found {show(ids)}")
    el = found[0]
    attrs = dict(el.attrib)
    child = el.find("carFollowing-CACC")
    model = attrs.get("carFollowModel")
    if child is not None:
        attrs.update(child.attrib)
        model = model or "CACC"
    if model != "CACC":
        raise StringStabError(
            f"--vtype {spec}: uses car-following model {model or 'Krauss (the default)'!r}; "
            "expected carFollowModel=\"CACC\"")
    params = dict(DEFAULTS)
    for key in DEFAULTS:
        if key in attrs:
            try:
                params[key] = float(attrs[key])
            except ValueError as e:
                raise StringStabError(
                    f"--vtype {spec}: {key} must be a number; got {attrs[key]!r}") from e
            if not math.isfinite(params[key]):
                raise StringStabError(f"--vtype {spec}: {key} must be finite; got {attrs[key]!r}")
    if params["tau"] <= 0 or params["minGap"] < 0 or params["length"] <= 0:
        raise StringStabError(
            f"--vtype {spec}: expected tau > 0, minGap >= 0, length > 0; got tau = "
            f"{params['tau']:g}, minGap = {params['minGap']:g}, length = {params['length']:g}")
    return CACCType(tid, str(Path(fname)), params, ET.tostring(el, encoding="unicode").strip())


@dataclass(frozen=True)
class ModeLaw:
    """One mode of the CACC gap-control law as a linear law (the module docstring).

    Attributes
    ----------
    mode, sumo_name : str
        The mode, and SUMO's name of it (the vehicle parameter ``caccVehicleMode``).
    g_space, g_speed : float
        SUMO's per-step gains (its vType parameters).
    k_p, k_d : float
        Acceleration gains on e and ė: g/h with h = max(Δt, 0.1 s), 1/s² and 1/s.
    k_x, k_v : float
        The equivalent eq-4 gains with the own-acceleration term solved for (k_a = 0).
    headway, standstill : float
        T* = the vType's tau (s) and l_0 = its minGap (m).
    """

    mode: str
    sumo_name: str
    g_space: float
    g_speed: float
    k_p: float
    k_d: float
    k_x: float
    k_v: float
    headway: float
    standstill: float

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready."""
        return dict(vars(self))


def mode_laws(vt: CACCType, dt: float) -> list[ModeLaw]:
    """The three gap-control modes of ``vt`` at step ``dt`` as linear laws.

    Parameters
    ----------
    vt : CACCType
        The CACC vType (from :func:`read_vtype`).
    dt : float
        SUMO's step (s); the per-step gains are divided by max(dt, 0.1 s).

    Returns
    -------
    list of ModeLaw
        One law per mode, in the order of ``MODES``.

    Raises
    ------
    StringStabError
        When 1 + k_d T ≤ 0 (the own-acceleration term makes the mode ill-posed).
    """
    h = max(float(dt), TUNED_STEP)
    T = vt.headway
    out = []
    for mode, (name, ks, kd) in MODES.items():
        gs, gd = vt.params[ks], vt.params[kd]
        k_p, k_d = gs / h, gd / h
        den = 1.0 + k_d * T
        if den <= 0:
            raise StringStabError(
                f"--vtype {vt.id}: in {mode} mode 1 + k_d T = {den:g} <= 0 ({kd} = {gd:g}); "
                "expected a positive rate gain")
        out.append(ModeLaw(mode, name, gs, gd, k_p, k_d, k_p / den, k_d / den, T, vt.min_gap))
    return out


def discrete_sweep(law: ModeLaw, dt: float, n: int = 20001) -> dict[str, Any]:
    """|H(e^{jθ})| of SUMO's exact per-mode discrete law on a fine grid (a sweep, not a proof).

    The vehicle is kinematic with its acceleration u_k held over the step (SUMO's ballistic
    update moves it exactly so); the law is u_k = k_p e_k + k_d (Δv_k − T u_{k−1}).  With
    P(z) = Δt²(z + 1)/(2(z − 1)²) and Q(z) = Δt/(z − 1) (position and speed per held
    acceleration), H(z) = U_i/U_{i−1} = (k_p P + k_d Q)/(1 + k_p (P + T Q) + k_d Q + k_d T/z),
    i.e. N(z)/D(z) with N = k_p Δt² z(z + 1) + 2 k_d Δt z(z − 1) and
    D = 2z(z − 1)² + N + 2 k_p T Δt z(z − 1) + 2 k_d T (z − 1)².

    Parameters
    ----------
    law : ModeLaw
        One mode's law (from :func:`mode_laws`).
    dt : float
        SUMO's step Δt (s).
    n : int, default 20001
        Number of grid points θ = π/n, ..., π.

    Returns
    -------
    dict
        ``schur`` (all roots of D inside the unit circle), ``spectral_radius``, ``sup_gain``
        (max over the grid θ ∈ (0, π]; None when not Schur), ``peak_omega`` (rad/s, θ/Δt at
        the grid maximum, reported even when not Schur), ``grid`` (``n``).
    """
    kp, kd, T, h = law.k_p, law.k_d, law.headway, float(dt)
    Np = np.polynomial.Polynomial
    z = Np([0.0, 1.0])
    num = kp * h * h * z * (z + 1) + 2 * kd * h * z * (z - 1)
    den = 2 * z * (z - 1) ** 2 + num + 2 * kp * T * h * z * (z - 1) + 2 * kd * T * (z - 1) ** 2
    roots = den.roots()
    rho = float(np.max(np.abs(roots)))
    theta = np.linspace(math.pi / n, math.pi, n)
    zz = np.exp(1j * theta)
    mag = np.abs(num(zz) / den(zz))
    k = int(np.argmax(mag))
    schur = rho < 1.0
    return {"schur": bool(schur), "spectral_radius": rho,
            "sup_gain": float(mag[k]) if schur else None,
            "peak_omega": float(theta[k] / h), "grid": n}


def _no_lag_closed_form(law: ModeLaw) -> dict[str, Any]:
    kx, kv, T = law.k_x, law.k_v, law.headway
    stable = kx > 0 and kv + kx * T > 0
    lhs = kx * T * T + 2 * kv * T
    return {"hurwitz": bool(stable), "kxT2_plus_2kvT": lhs,
            "string_stable": bool(stable and lhs >= 2.0 - 1e-12)}


def certify_modes(vt: CACCType, dt: float) -> list[dict[str, Any]]:
    """Each mode's law with its certificates.

    Continuous and sampled at ``dt`` (τ = 1 ms, δ = 0), the closed-form no-lag condition, and
    the exact discrete sweep.

    Parameters
    ----------
    vt : CACCType
        The CACC vType (from :func:`read_vtype`).
    dt : float
        SUMO's step (s).

    Returns
    -------
    list of dict
        Per mode: the :class:`ModeLaw` fields, ``continuous`` and ``sampled`` (verdict and sup
        gain of :func:`stringstab.certify.api.certify`), ``no_lag_closed_form`` (Hurwitz,
        k_x T*² + 2 k_v T* ≥ 2) and ``sumo_discrete_sweep`` (:func:`discrete_sweep`).

    Raises
    ------
    StringStabError
        When a mode is ill-posed (:func:`mode_laws`).
    """
    from ..certify.api import certify

    rows = []
    for law in mode_laws(vt, dt):
        c = certify(law.k_x, law.k_v, 0.0, tau=NO_LAG_TAU, delta=0.0, headway=law.headway)
        s = certify(law.k_x, law.k_v, 0.0, tau=NO_LAG_TAU, delta=0.0, headway=law.headway,
                    sample_time=dt)
        rows.append({**law.as_dict(),
                     "continuous": {"verdict": c.verdict, "sup_gain": c.sup_gain},
                     "sampled": {"verdict": s.verdict, "sup_gain": s.sup_gain, "sample_time": dt},
                     "no_lag_closed_form": _no_lag_closed_form(law),
                     "sumo_discrete_sweep": discrete_sweep(law, dt)})
    return rows


def law_residual(records: dict[str, Array], vt: CACCType, dt: float) -> dict[str, Any]:
    """How well the per-mode law reproduces SUMO's speeds in the recorded steps.

    ``records`` holds per step and follower: ``gap`` (bumper to bumper), ``v``, ``v_pred``,
    ``a`` (SUMO's acceleration before the step), ``v_next`` and ``mode`` (SUMO's name).

    Parameters
    ----------
    records : dict of str to ndarray
        The recorded steps, flat arrays of one length: ``gap`` (m), ``v``, ``v_pred``,
        ``v_next`` (m/s), ``a`` (m/s²), ``mode`` (str).
    vt : CACCType
        The CACC vType the followers use.
    dt : float
        SUMO's step (s).

    Returns
    -------
    dict
        Per mode: ``steps``, ``max_residual`` and ``median_residual`` of
        |v_next − max(v + (g_s e + g_d ė) Δt/h, 0)| (m/s, h = max(Δt, 0.1 s); None for a mode
        never used); a step where SUMO's safe speed or a bound overrode the mode shows as a
        large residual.
    """
    laws = {law.sumo_name: law for law in mode_laws(vt, dt)}
    h = max(dt, TUNED_STEP)
    out: dict[str, Any] = {}
    for name, law in laws.items():
        m = records["mode"] == name
        if not m.any():
            out[law.mode] = {"steps": 0, "max_residual": None, "median_residual": None}
            continue
        e = records["gap"][m] - law.standstill - law.headway * records["v"][m]
        edot = records["v_pred"][m] - records["v"][m] - law.headway * records["a"][m]
        pred = records["v"][m] + (law.g_space * e + law.g_speed * edot) * (dt / h)
        r = np.abs(records["v_next"][m] - np.maximum(pred, 0.0))
        out[law.mode] = {"steps": int(m.sum()), "max_residual": float(r.max()),
                         "median_residual": float(np.median(r))}
    return out


def measure_platoon(vt: CACCType, leader: Trajectory, n_followers: int, *,
                    api: str = "libsumo") -> dict[str, Any]:
    """Drive ``n_followers`` SUMO CACC vehicles behind a leader of the same vType; measure.

    The leader follows ``leader``'s speeds exactly (speed mode 0); the followers are SUMO's own
    CACC vehicles, inserted at the law's equilibrium gap s_0 + T v.  Their accelerations are
    SUMO's finite differences of speed, which for these lag-free vehicles are the held
    accelerations themselves.

    Parameters
    ----------
    vt : CACCType
        The vType of the leader and the followers.
    leader : Trajectory
        The leader's speed profile; its ``dt`` is SUMO's step (s).
    n_followers : int
        Number of CACC followers.
    api : {"libsumo", "traci"}, default "libsumo"
        How SUMO is driven.

    Returns
    -------
    dict
        ``m_p`` per follower (eq 29: follower over predecessor acceleration energy),
        ``max_m_p``, ``amplification`` (last follower over leader, RMS acceleration),
        ``mode_share`` (fraction of follower-steps in each mode), ``law_residual``
        (:func:`law_residual`), ``collisions``-free ``min_gap`` (m).
    """
    from ..traffic.metrics import damping_ratios_from_energy

    dt = float(leader.dt)
    T, s0, L = vt.headway, vt.min_gap, vt.length
    v0 = float(leader.speed[0])
    N = int(n_followers)
    gaps = np.full(N, s0 + T * v0)
    ids = [LEADER_ID, *follower_ids(N)]
    steps = leader.n_steps
    V = np.empty((steps, N + 1))
    X = np.empty((steps, N + 1))
    rec: dict[str, list[Any]] = {k: [] for k in ("gap", "v", "v_pred", "a", "v_next", "mode")}
    with tempfile.TemporaryDirectory(prefix="stringstab-sumo-cacc-") as tmp:
        road = straight_road(tmp, distance=float(leader.position[-1] - leader.position[0]),
                             gaps=gaps, speeds=np.full(N, v0), leader_speed=v0, length=L,
                             vtype=vt.xml, type_id=vt.id)
        with SumoSession(road.sumo_args(), dt=dt, api=api) as s:
            s.step()
            veh = s.vehicle
            present = set(veh.getIDList())
            missing = [v for v in ids if v not in present]
            if missing:
                raise StringStabError(f"SUMO did not insert {', '.join(missing)}")
            veh.setSpeedMode(LEADER_ID, 0)
            for vid in ids:
                veh.setLaneChangeMode(vid, 0)
            for k in range(steps):
                x = np.array([veh.getLanePosition(v) for v in ids])
                v = np.array([veh.getSpeed(v) for v in ids])
                a = np.array([veh.getAcceleration(v) for v in ids])
                X[k], V[k] = x, v
                if k == steps - 1:
                    break
                veh.setSpeed(LEADER_ID, float(leader.speed[k + 1]))
                s.step()
                v_next = np.array([veh.getSpeed(v) for v in ids[1:]])
                modes = [veh.getParameter(v, "caccVehicleMode") for v in ids[1:]]
                rec["gap"].append(x[:-1] - x[1:] - L)
                rec["v"].append(v[1:])
                rec["v_pred"].append(v[:-1])
                rec["a"].append(a[1:])
                rec["v_next"].append(v_next)
                rec["mode"].append(np.array(modes, dtype=object))
    acc = np.zeros_like(V)
    acc[1:] = np.diff(V, axis=0) / dt
    mp = damping_ratios_from_energy((acc * acc).sum(axis=0))
    records = {k: np.concatenate(v) if v else np.array([]) for k, v in rec.items()}
    mode_arr: Any = records["mode"]
    share = {m: float(np.mean(mode_arr == m)) for m in sorted(set(mode_arr.tolist()))}
    gap = X[:, :-1] - X[:, 1:] - L
    rms = np.sqrt((acc * acc).mean(axis=0))
    return {"followers": N, "leader": leader.name, "seconds": leader.duration, "dt": dt,
            "m_p": mp.tolist(), "max_m_p": float(np.max(mp)),
            "amplification": float(rms[-1] / rms[0]) if rms[0] > 0 else None,
            "mode_share": share, "law_residual": law_residual(records, vt, dt),
            "min_gap": float(gap.min())}
