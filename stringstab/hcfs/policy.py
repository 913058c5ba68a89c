"""Acceleration policies: the seam where the learned (DDPG) controller plugs into HCFS.

An *acceleration policy* is any callable mapping a batch of eq-3 states, shape ``(n, 6)`` in
SI units (:func:`stringstab.hcfs.mdp.state`), to ``n`` desired accelerations in m/s² (shape
``(n,)`` or ``(n, 1)``, as :func:`stringstab.rl.train`'s policies return).  An optional
``label`` attribute names it in reports.

* :class:`~stringstab.hcfs.cacc.CACC` — the eq-11 law;
* :class:`LeaderSpeedMatcher` — a deliberately imperfect, hand-written *stand-in* for the DDPG,
  used until a trained policy is plugged in (never reported as a DDPG);
* :class:`ScaledPolicy` — a network trained on the normalised state (the HCFS environment's
  observation) wrapped to take SI states;
* :func:`rate_limit` — what makes a candidate satisfy the theorem's premise |a_k − a_{k−1}| ≤ J T.
"""

from __future__ import annotations

from typing import Any, Protocol, runtime_checkable

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError
from .constants import ACCEL_MAX, ACCEL_MIN, DT
from .mdp import STATE_SCALES

__all__ = [
    "AccelerationPolicy",
    "LeaderSpeedMatcher",
    "ScaledPolicy",
    "accelerations",
    "policy_label",
    "rate_limit",
]

Array = npt.NDArray[np.float64]


@runtime_checkable
class AccelerationPolicy(Protocol):
    """A callable ``policy(state (n, 6)) -> accelerations (n,) or (n, 1)`` in m/s²."""

    def __call__(self, state: Array, /) -> Any:
        """The desired accelerations of a batch of states.

        Parameters
        ----------
        state : array (n, 6)
            Eq-3 states in SI units (:func:`stringstab.hcfs.mdp.state`).

        Returns
        -------
        array (n,) or (n, 1)
            Desired accelerations, m/s².
        """
        ...


def policy_label(policy: AccelerationPolicy) -> str:
    """The policy's ``label`` attribute, or its class name.

    Parameters
    ----------
    policy : AccelerationPolicy
        Any acceleration policy.

    Returns
    -------
    str
        Its non-empty ``label``, else its class name.

    Examples
    --------
    >>> policy_label(LeaderSpeedMatcher()).startswith("stand-in")
    True
    """
    return str(getattr(policy, "label", None) or type(policy).__name__)


def accelerations(policy: AccelerationPolicy, state: npt.ArrayLike) -> Array:
    """Call a policy on states of any batch shape ``(..., 6)``; returns accelerations ``(...)``.

    Parameters
    ----------
    policy : AccelerationPolicy
        ``policy(states (n, 6)) -> (n,) or (n, 1)`` accelerations, m/s².
    state : array_like (..., 6)
        Eq-3 states (:func:`stringstab.hcfs.mdp.state`), flattened to (n, 6) for the call.

    Returns
    -------
    array (...)
        The accelerations, m/s², in the batch shape of ``state``.

    Raises
    ------
    StringStabError
        If the state does not have 6 components, the policy raises a TypeError,
        ValueError or RuntimeError (torch's error for a wrong input shape), returns the wrong
        number of values or a NaN/inf.

    Examples
    --------
    >>> accelerations(lambda s: s[:, 5:6] + 1.0, np.zeros((2, 3, 6))).shape
    (2, 3)
    """
    s = np.asarray(state, dtype=np.float64)
    if s.ndim < 1 or s.shape[-1] != 6:
        raise StringStabError(f"the HCFS state (eq 3) has 6 components per vehicle; got shape {s.shape}")
    flat = s.reshape(-1, 6)
    try:
        out = np.asarray(policy(flat), dtype=np.float64)
    except (TypeError, ValueError, RuntimeError) as e:  # RuntimeError: torch's shape errors
        raise StringStabError(f"the acceleration policy {policy_label(policy)!r} failed on a state batch: {e}") from e
    if out.size != flat.shape[0]:
        raise StringStabError(
            f"an acceleration policy must return one acceleration per state ({flat.shape[0]}); "
            f"{policy_label(policy)!r} returned shape {out.shape}"
        )
    if not np.isfinite(out).all():
        raise StringStabError(f"the acceleration policy {policy_label(policy)!r} returned NaN or inf")
    return out.reshape(s.shape[:-1])


def rate_limit(raw: npt.ArrayLike, previous: npt.ArrayLike, step_limit: npt.ArrayLike, *,
               accel_min: float = ACCEL_MIN, accel_max: float = ACCEL_MAX) -> Array:
    """Limit a candidate to [a_min, a_max], then to previous ± J T (the theorem's premise).

    ``previous`` is the candidate's own (limited) value of the last frame and lies in
    [a_min, a_max], so the result lies between it and the clipped raw value: it satisfies both
    the acceleration bounds and |a_k − a_{k−1}| ≤ J T.

    Parameters
    ----------
    raw : array_like
        The candidate's unlimited acceleration a_k, m/s².
    previous : array_like
        Its limited value a_{k−1} of the last frame, m/s² (assumed in [a_min, a_max]; the
        bounds are not guaranteed otherwise).
    step_limit : float or array_like
        J T, m/s² (premises P1/P2 of the HCFS theorem, §III-C).
    accel_min, accel_max : float
        a_min, a_max, m/s².

    Returns
    -------
    array
        The limited acceleration, m/s².

    Examples
    --------
    >>> rate_limit([5.0, -0.2], [0.0, 0.0], 1.0).tolist()
    [1.0, -0.2]
    """
    p = np.asarray(previous, dtype=np.float64)
    lim = np.asarray(step_limit, dtype=np.float64)
    a = np.clip(np.asarray(raw, dtype=np.float64), accel_min, accel_max)
    return np.asarray(np.clip(a, p - lim, p + lim))


class LeaderSpeedMatcher:
    """A hand-written, deliberately imperfect stand-in for the DDPG: a = −κ e_v(k,0) / T.

    It drives the speed error to the leader (the reward's eq-4 term) towards zero with an
    overshoot for κ > 1 (κ = 1.5 alternates the sign of the error every frame: a zigzag like
    the one the paper reports for its DDPG), and it ignores the spacing altogether.  It exists
    to exercise the switch until a trained DDPG is plugged in; reports label it as a stand-in.

    Parameters
    ----------
    kappa : float
        κ, the fraction of the speed error removed per frame (1 is dead-beat).
    dt : float
        T, s.

    Examples
    --------
    >>> s = np.zeros((1, 6)); s[0, 3] = 0.2   # 0.2 m/s faster than the leader
    >>> round(float(LeaderSpeedMatcher(kappa=1.5, dt=0.2)(s)[0]), 6)
    -1.5
    """

    is_stand_in = True

    def __init__(self, kappa: float = 1.5, *, dt: float = DT) -> None:
        self.kappa = float(kappa)
        self.dt = float(dt)
        self.label = (f"stand-in: leader-speed matcher a = -{self.kappa:g} e_v(k,0)/T "
                      "(hand-written, deliberately imperfect; not a DDPG)")

    def __call__(self, state: Array) -> Array:
        """a = −κ e_v(k,0) / T for each state (no limits).

        Parameters
        ----------
        state : array (..., 6)
            Eq-3 states in SI units; component 3 is e_v(k,0), the speed error to the leader.

        Returns
        -------
        array (...)
            Desired accelerations, m/s².
        """
        return np.asarray(-self.kappa * np.asarray(state)[..., 3] / self.dt)


class ScaledPolicy:
    """A policy trained on the normalised eq-3 state, taking SI states.

    ``ScaledPolicy(net)(s) = net(s / scales)``; the HCFS environment
    (:class:`stringstab.hcfs.env.HCFSVectorEnv`) observes ``s / scales``.

    Parameters
    ----------
    policy : callable
        The trained network (e.g. ``TrainResult.policy`` of :mod:`stringstab.rl`).
    scales : sequence of 6 floats
        Divisors of the state components (default :data:`~stringstab.hcfs.mdp.STATE_SCALES`).
    label : str
        Name in reports.
    torch_threads : int, optional
        Run each call of a torch network with this many torch threads (restored afterwards).
        The batches are one row per follower: with the default thread pool on a busy 2-core
        machine a call took 9.4 ms, with one thread 0.67 ms (load 5.8).

    Examples
    --------
    >>> p = ScaledPolicy(lambda z: z[:, 5:6], label="identity on a/a_max")
    >>> p(np.array([[0, 0, 0, 0, 0, 1.5]])).tolist()
    [[0.5]]
    """

    def __init__(self, policy: AccelerationPolicy, scales: npt.ArrayLike = STATE_SCALES, *,
                 label: str = "DDPG", torch_threads: int | None = None) -> None:
        sc = np.asarray(scales, dtype=np.float64)
        if sc.shape != (6,) or not (np.isfinite(sc).all() and (sc > 0).all()):
            raise StringStabError(f"scales must be 6 finite numbers > 0; got {scales!r}")
        self.policy, self.scales, self.label = policy, sc, label
        self.torch_threads = torch_threads

    def __call__(self, state: Array) -> Any:
        """The wrapped network's output on the normalised states ``state / scales``.

        Parameters
        ----------
        state : array (n, 6)
            Eq-3 states in SI units.

        Returns
        -------
        Any
            What the network returns: accelerations, m/s², shape (n,) or (n, 1).
        """
        z = np.asarray(state, dtype=np.float64) / self.scales
        if self.torch_threads is None:
            return self.policy(z)
        try:
            import torch
        except ImportError:  # not a torch network after all
            return self.policy(z)
        before = torch.get_num_threads()
        if before == self.torch_threads:
            return self.policy(z)
        torch.set_num_threads(self.torch_threads)
        try:
            return self.policy(z)
        finally:
            torch.set_num_threads(before)
